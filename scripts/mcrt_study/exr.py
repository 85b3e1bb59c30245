"""Reading OpenEXR images with numpy and zlib alone: the scanline files mcrt writes.

mcrt writes 32-bit float RGB with ZIP compression (OpenImageIO's "zip"); this
reader takes single-part scanline images with no, ZIPS or ZIP compression and
half, float or uint channels, which is all the study needs without adding an
image library to the environment. Other files (tiled, multi-part, deep,
PIZ/PXR24/B44/DWA compression) raise ExrError.

File layout (openexr.com, "OpenEXR File Layout"): magic, version, header
attributes (name NUL type NUL size value) ending in a NUL, the offset table
(one uint64 per chunk), then chunks (int32 first line, int32 data size, data).
A chunk holds its lines one after another, each line its channels in the
header's (alphabetical) order, each channel `width` values. ZIP data is zlib
over the bytes split into even and odd positions and delta-coded; a chunk
whose data size equals the raw size is stored raw.
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

MAGIC = 20000630
COMPRESSION_NONE, COMPRESSION_RLE, COMPRESSION_ZIPS, COMPRESSION_ZIP = 0, 1, 2, 3
LINES_PER_CHUNK = {COMPRESSION_NONE: 1, COMPRESSION_ZIPS: 1, COMPRESSION_ZIP: 16}
# Pixel type in the channel list: numpy dtype (little-endian).
PIXEL_TYPES = {0: "<u4", 1: "<f2", 2: "<f4"}


class ExrError(ValueError):
    """A file this reader cannot read."""


def _cstring(data: bytes, pos: int) -> tuple[str, int]:
    end = data.index(b"\0", pos)
    return data[pos:end].decode("latin-1"), end + 1


def parse_header(data: bytes) -> tuple[dict, int]:
    """The header's attributes (raw bytes by name) and the offset just past the header."""
    if len(data) < 8 or struct.unpack_from("<i", data, 0)[0] != MAGIC:
        raise ExrError("not an OpenEXR file")
    version = struct.unpack_from("<I", data, 4)[0]
    if version & 0xFF != 2:
        raise ExrError(f"OpenEXR version {version & 0xFF} (expected 2)")
    if version & 0x200:
        raise ExrError("tiled OpenEXR images are not supported")
    if version & (0x800 | 0x1000):
        raise ExrError("multi-part or deep OpenEXR images are not supported")
    attrs: dict[str, tuple[str, bytes]] = {}
    pos = 8
    while data[pos] != 0:
        name, pos = _cstring(data, pos)
        kind, pos = _cstring(data, pos)
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        attrs[name] = (kind, data[pos:pos + size])
        pos += size
    return attrs, pos + 1


def parse_channels(raw: bytes) -> list[tuple[str, int, int, int]]:
    """The channel list: (name, pixel type, x sampling, y sampling) per channel, in file order."""
    channels = []
    pos = 0
    while raw[pos] != 0:
        name, pos = _cstring(raw, pos)
        pixel_type, _, xs, ys = struct.unpack_from("<iB3xii", raw, pos)  # type, pLinear, reserved
        pos += 16
        channels.append((name, pixel_type, xs, ys))
    return channels


def unzip_chunk(packed: bytes, raw_size: int) -> bytes:
    """The raw bytes of a ZIP/ZIPS chunk (stored raw when compression did not pay)."""
    if len(packed) == raw_size:
        return packed
    import numpy as np

    t = np.frombuffer(zlib.decompress(packed), dtype=np.uint8)
    if t.size != raw_size:
        raise ExrError(f"chunk decompresses to {t.size} bytes, expected {raw_size}")
    # Undo the predictor: each byte was stored as (b[i] - b[i-1] + 128) mod 256.
    d = t.astype(np.int64)
    d[1:] -= 128
    d = np.cumsum(d) & 0xFF
    # Undo the split: the first half holds the even positions, the second the odd ones.
    out = np.empty(raw_size, dtype=np.uint8)
    half = (raw_size + 1) // 2
    out[0::2] = d[:half]
    out[1::2] = d[half:]
    return out.tobytes()


def read_exr(path: Path | str) -> dict:
    """The channels of a scanline OpenEXR file as float32 arrays (height x width) by name."""
    import numpy as np

    data = Path(path).read_bytes()
    attrs, pos = parse_header(data)
    for name in ("channels", "compression", "dataWindow"):
        if name not in attrs:
            raise ExrError(f"header lacks '{name}'")
    channels = parse_channels(attrs["channels"][1])
    compression = attrs["compression"][1][0]
    if compression not in LINES_PER_CHUNK:
        raise ExrError(f"compression {compression} is not supported (none, ZIPS and ZIP are)")
    xmin, ymin, xmax, ymax = struct.unpack("<iiii", attrs["dataWindow"][1])
    width, height = xmax - xmin + 1, ymax - ymin + 1
    for name, pixel_type, xs, ys in channels:
        if pixel_type not in PIXEL_TYPES:
            raise ExrError(f"channel {name}: pixel type {pixel_type}")
        if (xs, ys) != (1, 1):
            raise ExrError(f"channel {name}: subsampled channels are not supported")
    dtypes = [np.dtype(PIXEL_TYPES[t]) for _, t, _, _ in channels]
    line_bytes = sum(width * dt.itemsize for dt in dtypes)
    lines = LINES_PER_CHUNK[compression]
    chunks = (height + lines - 1) // lines
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    planes = {name: np.empty((height, width), dtype=np.float32) for name, _, _, _ in channels}
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        first = y - ymin
        count = min(lines, height - first)
        if not 0 <= first < height:
            raise ExrError(f"chunk at line {y} lies outside the data window")
        packed = data[offset + 8:offset + 8 + size]
        raw = packed if compression == COMPRESSION_NONE else unzip_chunk(packed, count * line_bytes)
        at = 0
        for line in range(count):
            for (name, _, _, _), dt in zip(channels, dtypes):
                values = np.frombuffer(raw, dtype=dt, count=width, offset=at)
                planes[name][first + line] = values.astype(np.float32)
                at += width * dt.itemsize
    return planes


def read_rgb(path: Path | str):
    """An OpenEXR image as a float32 array (height x width x 3) of its R, G and B channels
    (a single Y channel, grey, repeated)."""
    import numpy as np

    planes = read_exr(path)
    if all(c in planes for c in "RGB"):
        return np.stack([planes["R"], planes["G"], planes["B"]], axis=-1)
    if "Y" in planes:
        return np.repeat(planes["Y"][..., None], 3, axis=-1)
    raise ExrError(f"{path}: no R, G, B (or Y) channels: {', '.join(sorted(planes))}")
