#pragma once
// PLY meshes (Turk 1994, "The PLY Polygon File Format"; as pbrt-v4's
// plymesh reads them, src/pbrt/util/mesh.cpp): ASCII, binary little- and
// big-endian, gzip-compressed (.ply.gz); the vertex element's x y z, nx ny
// nz (shading normals) and u v (or s t, texture_u texture_v, texture_s
// texture_t); faces as lists of 3 or 4 vertex indices ("vertex_indices" or
// "vertex_index"). Other elements and properties (colours, edges) are read
// over: pbrt-v4 does not use them either.
//
// Quads: a PLY quad v0 v1 v2 v3 is pbrt-v4's bilinear patch v0 v1 v3 v2. A
// planar convex one is the same surface as the triangles v0 v1 v2 and v0 v2
// v3, which is what the reader makes; a non-planar or non-convex quad is
// refused (mcrt has no bilinear patches).
#include <string>

#include "input_file.hpp"
#include "mcrt/geometry/triangle_mesh.hpp"
#include "pbrt/tokenizer.hpp"

namespace mcrt::pbrt {

struct ply_stats {
  std::size_t vertices = 0, triangles = 0, quads = 0;
};

// The mesh of a PLY file; throws parse_error naming the PLY file (and the
// header line, or the element, where the problem is): unreadable or
// truncated files, unknown formats or types, missing x y z or faces,
// indices out of range, non-finite coordinates, normals or uv, faces other
// than triangles and quads, non-planar quads.
// The file is read as src/input_file.hpp reads files: only a regular file,
// at most max_bytes bytes of it (unpacked, for .ply.gz); its header is read
// and checked against the file's size before the data is.
triangle_mesh read_ply(const std::string& path, std::uint64_t max_bytes = io::default_max_input_bytes,
                       ply_stats* stats = nullptr);

// The same from the bytes of a PLY file held in memory (`name` in errors).
triangle_mesh read_ply_bytes(const std::string& bytes, const std::string& name, ply_stats* stats = nullptr);

}  // namespace mcrt::pbrt
