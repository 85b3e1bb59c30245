// The PLY reader (src/pbrt/ply.cpp): one mesh written as ASCII, binary
// little-endian, binary big-endian and gzip-compressed gives the same
// positions, normals, uv and triangles (quads split, a quad with a repeated
// corner a triangle, other elements and properties read over); bad files are
// refused with one line naming the PLY file (truncated data or header,
// unknown formats and types, indices out of range, non-finite coordinates,
// faces of five vertices, non-planar quads); and 100000 seeded mutations of
// an ASCII and a binary file give a mesh or a parse_error, never a crash,
// a hang or another exception.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "mcrt/core/rng.hpp"
#include "pbrt/ply.hpp"

using namespace mcrt;
using namespace mcrt::pbrt;
namespace fs = std::filesystem;

namespace {

// The test mesh: 5 vertices with normals and uv, a triangle, a planar quad,
// a quad with a repeated corner; an extra colour property and an edge
// element to be read over.
const float xyz[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0.5f, 0}};
const std::vector<std::vector<int>> faces = {{1, 4, 2}, {0, 1, 2, 3}, {1, 4, 4, 2}};

std::string header(const std::string& format) {
  return "ply\nformat " + format + " 1.0\ncomment made by a test\n"
         "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
         "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n"
         "property float u\nproperty float v\n"
         "element face 3\nproperty list uchar int vertex_indices\nproperty int flags\n"
         "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n";
}

std::string ascii_ply() {
  std::string s = header("ascii");
  // (Appended piece by piece: GCC 12 flags to_string() + " " + ... with a
  // false -Wrestrict, bug 105329.)
  for (int i = 0; i < 5; ++i) {
    for (int c = 0; c < 3; ++c) {
      s += std::to_string(xyz[i][c]);
      s += ' ';
    }
    s += "0 0 1 255 ";
    s += std::to_string(0.25f * float(i));
    s += ' ';
    s += std::to_string(1.0f - 0.25f * float(i));
    s += '\n';
  }
  for (const auto& f : faces) {
    s += std::to_string(f.size());
    for (int v : f) {
      s += ' ';
      s += std::to_string(v);
    }
    s += " 7\n";
  }
  return s + "0 1\n";
}

template <class T>
void put(std::string& s, T v, bool big) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));
  if (big == (std::endian::native == std::endian::little)) std::reverse(raw, raw + sizeof(T));
  s.append(reinterpret_cast<const char*>(raw), sizeof(T));
}

std::string binary_ply(bool big) {
  std::string s = header(big ? "binary_big_endian" : "binary_little_endian");
  for (int i = 0; i < 5; ++i) {
    for (int k = 0; k < 3; ++k) put<float>(s, xyz[i][k], big);
    put<float>(s, 0, big), put<float>(s, 0, big), put<float>(s, 1, big);
    put<std::uint8_t>(s, 255, big);
    put<float>(s, 0.25f * float(i), big), put<float>(s, 1.0f - 0.25f * float(i), big);
  }
  for (const auto& f : faces) {
    put<std::uint8_t>(s, static_cast<std::uint8_t>(f.size()), big);
    for (int v : f) put<std::int32_t>(s, v, big);
    put<std::int32_t>(s, 7, big);
  }
  put<std::int32_t>(s, 0, big), put<std::int32_t>(s, 1, big);
  return s;
}

void expect_test_mesh(const triangle_mesh& m, const std::string& what) {
  ASSERT_EQ(m.p.size(), 5u) << what;
  for (int i = 0; i < 5; ++i) EXPECT_EQ(m.p[std::size_t(i)], vec3(xyz[i][0], xyz[i][1], xyz[i][2])) << what;
  ASSERT_EQ(m.n.size(), 5u) << what;
  EXPECT_EQ(m.n[3], vec3(0, 0, 1)) << what;
  ASSERT_EQ(m.uv.size(), 5u) << what;
  EXPECT_NEAR(m.uv[2].x, 0.5f, 1e-6f) << what;
  EXPECT_NEAR(m.uv[2].y, 0.5f, 1e-6f) << what;
  // In face order: the triangle, the quad's two triangles (v0 v1 v2, v0 v2
  // v3), the repeated-corner quad's triangle.
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{1, 4, 2, 0, 1, 2, 0, 2, 3, 1, 4, 2})) << what;
}

std::string error_of(const std::string& bytes) {
  try {
    read_ply_bytes(bytes, "mesh.ply");
  } catch (const parse_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Ply, EveryFormatGivesTheSameMesh) {
  ply_stats st;
  expect_test_mesh(read_ply_bytes(ascii_ply(), "a.ply", &st), "ascii");
  EXPECT_EQ(st.vertices, 5u);
  EXPECT_EQ(st.triangles, 4u);
  EXPECT_EQ(st.quads, 1u);
  expect_test_mesh(read_ply_bytes(binary_ply(false), "le.ply"), "binary little-endian");
  expect_test_mesh(read_ply_bytes(binary_ply(true), "be.ply"), "binary big-endian");
  // From files, gzip-compressed too.
  const fs::path dir = fs::temp_directory_path() / ("mcrt_ply_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path plain = dir / "m.ply", gz = dir / "m.ply.gz";
  std::ofstream(plain, std::ios::binary) << binary_ply(false);
  const std::string bytes = binary_ply(true);
  gzFile f = gzopen(gz.string().c_str(), "wb");
  ASSERT_NE(f, nullptr);
  gzwrite(f, bytes.data(), static_cast<unsigned>(bytes.size()));
  gzclose(f);
  expect_test_mesh(read_ply(plain.string()), "file");
  expect_test_mesh(read_ply(gz.string()), "gzip file");
  fs::remove_all(dir);
}

TEST(Ply, BadFilesAreRefusedWithOneLineNamingTheFile) {
  const std::string good = binary_ply(false);
  const std::string ascii = ascii_ply();
  std::string nan_ascii = ascii;
  nan_ascii.replace(nan_ascii.find("end_header\n") + 11, 1, "nan");
  std::string out_of_range = ascii;
  out_of_range.replace(out_of_range.find("3 1 4 2"), 7, "3 1 9 2");
  std::string five = ascii;
  five.replace(five.find("3 1 4 2 7"), 9, "5 0 1 2 3 4 7");
  std::string bent = ascii;
  bent.replace(bent.find("\n0.000000 1.000000 0.000000"), 27, "\n0.000000 1.000000 0.300000");
  const std::pair<std::string, const char*> bad[] = {
      {good.substr(0, good.size() - 9), "truncated"},
      {good.substr(0, good.find("end_header")), "no end_header"},
      {"plx\n", "not a PLY file"},
      {"ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown format"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n", "unknown property type"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
       "no x, y and z"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0 1 0 0 0 1 0\n",
       "no face element"},
      {"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
       "more than the file holds"},
      {nan_ascii, "not a number"},
      {out_of_range, "vertex index 9 out of range"},
      {five, "a face of 5 vertices"},
      {bent, "face 1: a quad that is not planar and convex"},
  };
  for (const auto& [bytes, needle] : bad) {
    const std::string e = error_of(bytes);
    EXPECT_EQ(e.rfind("mesh.ply:", 0), 0u) << needle << " -> " << e;
    EXPECT_NE(e.find(needle), std::string::npos) << needle << " -> " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  // A non-finite coordinate written in binary.
  std::string inf_bin = good;
  const float inf = std::numeric_limits<float>::infinity();
  std::memcpy(inf_bin.data() + good.find("end_header\n") + 11, &inf, 4);
  EXPECT_NE(error_of(inf_bin).find("not finite"), std::string::npos) << error_of(inf_bin);
}

// Seeded mutations (bytes replaced, inserted, deleted, the file cut) of the
// ASCII and the binary file, 50000 each: a mesh or a parse_error naming
// the file, on one line.
TEST(Ply, FuzzedFilesGiveAMeshOrOneLineErrors) {
  pcg32 rng(2031, 9);
  int ok = 0, refused = 0;
  for (const std::string& base : {ascii_ply(), binary_ply(false)})
    for (int i = 0; i < 50000; ++i) {
      std::string s = base;
      const int edits = 1 + static_cast<int>(rng.uniform() * 4);
      for (int k = 0; k < edits && !s.empty(); ++k) {
        const std::size_t at = static_cast<std::size_t>(rng.uniform() * float(s.size()));
        const char c = static_cast<char>(rng.next_u32() & 0xff);
        switch (static_cast<int>(rng.uniform() * 4)) {
          case 0: s[at] = c; break;
          case 1: s.insert(s.begin() + static_cast<std::ptrdiff_t>(at), c); break;
          case 2: s.erase(at, 1 + static_cast<std::size_t>(rng.uniform() * 4)); break;
          default: s.resize(at); break;
        }
      }
      try {
        read_ply_bytes(s, "fuzz.ply");
        ++ok;
      } catch (const parse_error& e) {
        const std::string what = e.what();
        ASSERT_EQ(what.rfind("fuzz.ply:", 0), 0u) << what;
        ASSERT_EQ(what.find('\n'), std::string::npos) << what;
        ++refused;
      }
    }
  std::printf("fuzz: %d meshes read, %d refused\n", ok, refused);
  EXPECT_GT(ok, 1000);
  EXPECT_GT(refused, 10000);
}
