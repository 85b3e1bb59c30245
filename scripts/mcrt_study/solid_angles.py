"""Solid angles (steradians) of lights seen from a point."""

from __future__ import annotations

import math


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def triangle_solid_angle(p, a, b, c) -> float:
    """Solid angle of a triangle from p (Van Oosterom and Strackee 1983)."""
    r1, r2, r3 = _sub(a, p), _sub(b, p), _sub(c, p)
    l1, l2, l3 = (math.sqrt(_dot(r, r)) for r in (r1, r2, r3))
    numerator = abs(_dot(r1, _cross(r2, r3)))
    denominator = l1 * l2 * l3 + _dot(r1, r2) * l3 + _dot(r1, r3) * l2 + _dot(r2, r3) * l1
    return 2.0 * math.atan2(numerator, denominator)


def polygon_solid_angle(p, corners) -> float:
    """Solid angle of a convex planar polygon (corners in order) from p: a fan of triangles."""
    return sum(triangle_solid_angle(p, corners[0], corners[i], corners[i + 1]) for i in range(1, len(corners) - 1))


def disk_solid_angle_on_axis(distance: float, radius: float) -> float:
    """Solid angle of a disk from a point on its axis: 2 pi (1 - h / sqrt(h^2 + R^2))."""
    h = abs(distance)
    return 2.0 * math.pi * (1.0 - h / math.sqrt(h * h + radius * radius))


def ellipse_solid_angle(p, centre, axis1, axis2, n: int = 4096) -> float:
    """Solid angle of an ellipse from p, as that of an n-gon of the same area inscribed in its shape (the
    solid angle of a planar figure depends on its outline only): a fan of triangles from the centre."""
    import numpy as np
    phi = np.arange(n + 1) / n * 2 * np.pi
    stretch = math.sqrt(math.pi / (n / 2 * math.sin(2 * math.pi / n)))  # n-gon area = ellipse area
    c, a1, a2 = (np.asarray(v, float) for v in (centre, axis1, axis2))
    ring = c + stretch * (np.cos(phi)[:, None] * a1 + np.sin(phi)[:, None] * a2)
    r1 = c - np.asarray(p, float)
    r2, r3 = ring[:-1] - np.asarray(p, float), ring[1:] - np.asarray(p, float)
    l1, l2, l3 = np.linalg.norm(r1), np.linalg.norm(r2, axis=1), np.linalg.norm(r3, axis=1)
    numerator = np.abs(np.cross(r2, r3) @ r1)
    denominator = l1 * l2 * l3 + (r2 @ r1) * l3 + (r3 @ r1) * l2 + np.einsum("ij,ij->i", r2, r3) * l1
    return float(np.sum(2.0 * np.arctan2(numerator, denominator)))


def sphere_solid_angle(distance: float, radius: float) -> float:
    """Solid angle of a sphere from a point at `distance` from its centre: 2 pi (1 - sqrt(1 - (r/d)^2));
    4 pi from inside or on it."""
    if distance <= radius:
        return 4.0 * math.pi
    return 2.0 * math.pi * (1.0 - math.sqrt(1.0 - (radius / distance) ** 2))


def triangles_solid_angles(p, triangles):
    """Solid angles of many triangles from p (triangle_solid_angle for an array (n, 3, 3) of
    their corners; numpy)."""
    import numpy as np

    t = np.asarray(triangles, float) - np.asarray(p, float)
    r1, r2, r3 = t[:, 0], t[:, 1], t[:, 2]
    l1, l2, l3 = (np.linalg.norm(r, axis=1) for r in (r1, r2, r3))
    numerator = np.abs(np.einsum("ij,ij->i", r1, np.cross(r2, r3)))
    dot = lambda a, b: np.einsum("ij,ij->i", a, b)  # noqa: E731
    denominator = l1 * l2 * l3 + dot(r1, r2) * l3 + dot(r1, r3) * l2 + dot(r2, r3) * l1
    return 2.0 * np.arctan2(numerator, denominator)
