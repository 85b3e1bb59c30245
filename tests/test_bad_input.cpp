// Inputs from the web through the whole executable: files that crashed,
// aborted, hung or broke the one-line rule once (a black-box fuzz of `mcrt
// render` found them), each kept here as a reproducer (tests/bad_input/;
// special files, bombs and huge numbers are made by the test). Bad input
// gets one line on stderr naming the file, the place and the reason, exit
// status 2 and no output touched; valid input, however extreme, renders
// with no non-finite sample. The whole-program fuzz harness
// (tests/fuzz.py, ctest fuzz_quick) covers the classes; these pin the
// cases.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct result {
  int status;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fs::path input(const std::string& name) { return fs::path(MCRT_SOURCE_DIR) / "tests" / "bad_input" / name; }

const char* const light_selections[] = {"uniform", "power", "bvh", "pbrt-bvh"};

// The executable under test: the build's, or $MCRT_EXE (to run these
// reproducers against another build, an older commit's say).
std::string executable() {
  const char* e = std::getenv("MCRT_EXE");
  return e && *e ? e : MCRT_EXE;
}

class BadInput : public ::testing::Test {
 protected:
  fs::path dir;

  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir = fs::temp_directory_path() / ("mcrt_bad_input_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  // The executable with `args`, killed after 60 s (a hang fails the test
  // instead of stopping the suite).
  result run(const std::string& args) const {
    const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    const std::string cmd = "cd " + dir.string() + " && timeout -s KILL 60 " + executable() + " " + args + " >" +
                            out.string() + " 2>" + err.string() + " </dev/null";
    const int raw = std::system(cmd.c_str());
    result r{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
    fs::remove(out);
    fs::remove(err);
    return r;
  }

  fs::path write(const std::string& name, const std::string& bytes) const {
    const fs::path p = dir / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }

  // `mcrt render scene` at 8 x 8, 1 spp must refuse: exit 2, one line on
  // stderr starting "mcrt: ", under 1000 bytes, holding every needle, and
  // the output and stats files that existed beforehand untouched, with no
  // temporary left beside them.
  void expect_refused(const std::string& scene, std::initializer_list<std::string> needles,
                      const std::string& extra = "") const {
    const fs::path out = dir / "out.png", stats = dir / "stats.json";
    std::ofstream(out, std::ios::binary) << "previous contents";
    std::ofstream(stats, std::ios::binary) << "previous stats";
    const result r = run("render " + scene + " -o " + out.string() + " --stats " + stats.string() +
                         " --width 8 --height 8 --spp 1 --quiet " + extra);
    EXPECT_EQ(r.status, 2) << scene << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line expected, got: " << r.err;
    EXPECT_EQ(r.err.rfind("mcrt: ", 0), 0u) << r.err;
    EXPECT_LT(r.err.size(), 1000u) << r.err.substr(0, 300);
    EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
    for (const auto& n : needles) EXPECT_NE(r.err.find(n), std::string::npos) << "'" << n << "' not in: " << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_EQ(slurp(out), "previous contents") << "the output file was touched";
    EXPECT_EQ(slurp(stats), "previous stats") << "the stats file was touched";
    for (const auto& e : fs::directory_iterator(dir))
      EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "temporary left: " << e.path();
  }

  // `mcrt render scene` must render with no non-finite sample; returns its
  // --stats.
  nlohmann::json expect_renders(const std::string& scene, const std::string& args = "--width 8 --height 8 --spp 1",
                                const std::string& output = "out.exr") const {
    const fs::path out = dir / output, stats = dir / "stats.json";
    const result r = run("render " + scene + " -o " + out.string() + " --stats " + stats.string() + " --quiet " + args);
    EXPECT_EQ(r.status, 0) << scene << " " << args << "\nstderr: " << r.err;
    EXPECT_TRUE(fs::exists(out));
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(slurp(stats));
      EXPECT_EQ(j.at("nonfinite_samples").get<long long>(), 0) << scene << " " << args;
    } catch (const std::exception& e) {
      ADD_FAILURE() << scene << ": no stats: " << e.what();
    }
    return j;
  }

  // A gzip file of `members` concatenated gzip streams, each of `member`
  // bytes of c, after the text `head` (its own first member).
  fs::path gzip_bomb(const std::string& name, const std::string& head, char c, std::size_t member, int members) const {
    std::string block;
    {
      const std::string raw(member, c);
      uLongf size = compressBound(static_cast<uLong>(raw.size())) + 64;
      std::vector<unsigned char> buf(size);
      z_stream z{};
      deflateInit2(&z, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY);  // + 16: a gzip header and trailer
      z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(raw.data()));
      z.avail_in = static_cast<uInt>(raw.size());
      z.next_out = buf.data();
      z.avail_out = static_cast<uInt>(buf.size());
      EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
      block.assign(reinterpret_cast<const char*>(buf.data()), z.total_out);
      deflateEnd(&z);
    }
    const fs::path p = dir / name;
    gzFile f = gzopen(p.c_str(), "wb");
    gzwrite(f, head.data(), static_cast<unsigned>(head.size()));
    gzclose(f);
    std::ofstream out(p, std::ios::binary | std::ios::app);
    for (int i = 0; i < members; ++i) out << block;
    return p;
  }
};

}  // namespace

// Camera matrices that collapse space, an axis, or are projective are
// refused at the Camera directive; they once rendered black, or gave NaN
// rays that overflowed the BVH traversal's stack (a segfault).
TEST_F(BadInput, SingularAndProjectiveCamerasAreRefused) {
  expect_refused(input("camera_scale_zero.pbrt").string(), {"camera_scale_zero.pbrt:4: Camera", "singular"});
  expect_refused(input("camera_scale_axis.pbrt").string(), {"camera_scale_axis.pbrt:4: Camera", "singular"});
  expect_refused(input("camera_projective.pbrt").string(), {"camera_projective.pbrt:4: Camera", "not affine"});
}

// A uniform scale of the camera, however small, is not singular: the same
// view as without it, up to the rounding of the rays.
TEST_F(BadInput, TinyUniformCameraScaleRendersTheSameImage) {
  const std::string args = "--width 24 --height 24 --spp 16 --max-depth 2 --seed 3";
  expect_renders(input("camera_tiny_scale.pbrt").string(), args, "tiny.exr");
  expect_renders(input("camera_unit_scale.pbrt").string(), args, "unit.exr");
  const result d = run("diff " + (dir / "tiny.exr").string() + " " + (dir / "unit.exr").string() + " --json");
  ASSERT_EQ(d.status, 0) << d.err;
  const nlohmann::json j = nlohmann::json::parse(d.out);
  EXPECT_LT(std::abs(j.at("mean_diff_percent").get<double>()), 0.5) << d.out;
  EXPECT_LT(j.at("relmse").get<double>(), 1e-3) << d.out;
}

// A vertex at FLT_MAX in a mesh with shading normals, beside ordinary
// meshes, is valid: it renders with every light selection and integrator
// (it once overflowed the BVH traversal's stack).
TEST_F(BadInput, HugeVertexRenders) {
  for (const char* select : light_selections)
    for (const char* integrator : {"mis", "nee", "mixture"})
      expect_renders(input("huge_vertex.pbrt").string(), std::string("--width 16 --height 16 --spp 2 --light-select ") +
                                                             select + " --integrator " + integrator);
}

TEST_F(BadInput, NegativeLightScaleIsRefused) {
  expect_refused(input("light_negative_scale.pbrt").string(),
                 {"light_negative_scale.pbrt:5: AreaLightSource \"diffuse\": \"float scale\" must be >= 0"});
}

// Lights that all emit nothing render black with every light selection
// (bvh once threw from a worker thread: an abort).
TEST_F(BadInput, LightsThatEmitNothingRenderBlack) {
  for (const char* scene : {"lights_all_black.json", "lights_all_black.pbrt"})
    for (const char* select : light_selections)
      for (const char* integrator : {"mis", "nee", "mixture"}) {
        expect_renders(input(scene).string(),
                       std::string("--width 8 --height 8 --spp 2 --light-select ") + select + " --integrator " + integrator,
                       "black.ppm");
        // The plain PPM (P3): its header, then every pixel's values, all 0.
        std::istringstream ppm(slurp(dir / "black.ppm"));
        std::string magic;
        int w = 0, h = 0, maxval = 0;
        ppm >> magic >> w >> h >> maxval;
        ASSERT_EQ(magic, "P3");
        ASSERT_EQ(w * h, 64);
        int values = 0, nonzero = 0;
        for (int v; ppm >> v; ++values) nonzero += v != 0;
        EXPECT_EQ(values, 3 * 64);
        EXPECT_EQ(nonzero, 0) << scene << " " << select << " " << integrator;
      }
}

// Devices, FIFOs and directories are refused before they are read (an
// image texture of /dev/zero once spun for minutes in the image library;
// an Include of it read 4 GB; a FIFO waits for ever).
TEST_F(BadInput, SpecialFilesAreRefusedBeforeTheyAreRead) {
  expect_refused(input("texture_dev_zero.pbrt").string(), {"texture_dev_zero.pbrt:6", "/dev/zero", "not a regular file"});
  expect_refused(input("include_dev_zero.pbrt").string(), {"include_dev_zero.pbrt:5", "/dev/zero", "not a regular file"});
  expect_refused(input("ply_dev_zero.pbrt").string(), {"ply_dev_zero.pbrt:5", "/dev/zero", "not a regular file"});
  ASSERT_EQ(::mkfifo((dir / "fifo.pbrt").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir / "fifo.json").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir / "fifo.png").c_str(), 0600), 0);
  expect_refused((dir / "fifo.pbrt").string(), {"fifo.pbrt", "a FIFO"});
  expect_refused((dir / "fifo.json").string(), {"fifo.json", "a FIFO"});
  write("inc.pbrt", "LookAt 0 0 -3 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\nInclude \"fifo.pbrt\"\n");
  expect_refused((dir / "inc.pbrt").string(), {"inc.pbrt:4", "a FIFO"});
  fs::create_directories(dir / "folder.png");
  for (const char* image : {"fifo.png", "folder.png"}) {
    write("tex.pbrt", std::string("LookAt 0 0 -3 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\nTexture \"t\" \"spectrum\" "
                                  "\"imagemap\" \"string filename\" \"") +
                          image + "\"\nShape \"sphere\"\n");
    expect_refused((dir / "tex.pbrt").string(), {"tex.pbrt:4", image});
  }
  // mcrt diff reads only regular image files.
  const result d = run("diff /dev/zero /dev/zero");
  EXPECT_EQ(d.status, 2) << d.err;
  EXPECT_NE(d.err.find("/dev/zero: is a device"), std::string::npos) << d.err;
}

// A 3 MB gzip file that unpacks to 3 GiB is refused at the size bound
// (1 GiB by default; --max-input-size sets it), and a PLY header is
// checked against what the file can hold before its body is read.
TEST_F(BadInput, BombsAndOversizedFilesAreRefusedAtTheSizeBound) {
  gzip_bomb("bomb.pbrt.gz", "LookAt 0 0 -3 0 0 0 0 1 0\n", ' ', std::size_t(64) << 20, 48);
  expect_refused((dir / "bomb.pbrt.gz").string(), {"bomb.pbrt.gz", "unpacks to more than", "--max-input-size"});
  // A PLY whose header claims more vertices than the bound leaves room
  // for, its body an endless run of zeros: refused from its header.
  gzip_bomb("bomb.ply.gz", "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
            '\0', std::size_t(64) << 20, 48);
  write("ply_bomb.pbrt", "LookAt 0 0 -3 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\nShape \"plymesh\" \"string filename\" \"bomb.ply.gz\"\n");
  expect_refused((dir / "ply_bomb.pbrt").string(), {"ply_bomb.pbrt:4", "bomb.ply.gz:3: PLY", "1000000000 entries"});
  // A plain file over the bound.
  write("big.pbrt", "LookAt 0 0 -3 0 0 0 0 1 0\n" + std::string(4096, ' ') + "\nWorldBegin\nShape \"sphere\"\n");
  expect_refused((dir / "big.pbrt").string(), {"big.pbrt", "more than the input size bound of 2048 bytes"},
                 "--max-input-size 2K");
  expect_renders((dir / "big.pbrt").string(), "--width 8 --height 8 --spp 1 --max-input-size 8K");
  expect_refused((dir / "big.pbrt").string(), {"--max-input-size"}, "--max-input-size 12Q");
}

// An empty file, one of comments or white space only, and an empty
// .pbrt.gz are refused naming the file (they once said "<input>").
TEST_F(BadInput, EmptyFilesNameTheFile) {
  for (const char* name : {"empty.pbrt", "comments_only.pbrt", "whitespace_only.pbrt"})
    expect_refused(input(name).string(), {std::string(name) + ":1: the file has no directives"});
  gzFile f = gzopen((dir / "empty.pbrt.gz").c_str(), "wb");
  gzclose(f);
  expect_refused((dir / "empty.pbrt.gz").string(), {"empty.pbrt.gz:1: the file has no directives"});
  write("empty.json", "");
  expect_refused((dir / "empty.json").string(), {"empty.json", "invalid JSON"});
}

// A truncated PNG texture: one line (once the PNG library's own line came
// first, and mcrt's held a literal "\n").
TEST_F(BadInput, TruncatedPngIsOneLine) {
  const fs::path out = dir / "out.png";
  expect_refused(input("texture_truncated_png.pbrt").string(), {"texture_truncated_png.pbrt:6", "truncated.png"});
  const result r = run("render " + input("texture_truncated_png.pbrt").string() + " -o " + out.string() + " --quiet");
  EXPECT_EQ(r.err.find("libpng"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("\\n"), std::string::npos) << r.err;
}

// CR-only line endings (comments end at CR) and a UTF-8 byte-order mark
// (an extension: pbrt-v4 refuses it) render; a CR counts as a line break
// in messages.
TEST_F(BadInput, CrLineEndingsAndByteOrderMarkRender) {
  expect_renders(input("cr_line_endings.pbrt").string());
  expect_renders(input("byte_order_mark.pbrt").string());
  write("cr_error.pbrt", "# line 1\rLookAt 0 0 -3 0 0 0 0 1 0\rCamera \"perspective\"\rWorldBegin\rShape \"curve\"\r");
  expect_refused((dir / "cr_error.pbrt").string(), {"cr_error.pbrt:5: Shape \"curve\""});
  write("crlf.pbrt", "# line 1\r\nLookAt 0 0 -3 0 0 0 0 1 0\r\nCamera \"perspective\"\r\nWorldBegin\r\nShape \"curve\"\r\n");
  expect_refused((dir / "crlf.pbrt").string(), {"crlf.pbrt:5: Shape \"curve\""});
  write("bom.json", "\xEF\xBB\xBF" + slurp(input("lights_all_black.json")));
  expect_renders((dir / "bom.json").string());
}

// A 100,000-digit number is quoted by its beginning: the line stays short.
TEST_F(BadInput, HugeTokensAreQuotedByTheirBeginning) {
  write("long_number.pbrt", "Translate 1 2 " + std::string(100000, '7') + "\nWorldBegin\n");
  expect_refused((dir / "long_number.pbrt").string(), {"long_number.pbrt:1: Translate", "100000 bytes", "not a finite number"});
  write("long_word.pbrt", std::string(100000, 'W') + "\n");
  expect_refused((dir / "long_word.pbrt").string(), {"long_word.pbrt:1: unknown directive", "100000 bytes"});
  write("float_overflow.pbrt", "Translate 1 2 1e39\nWorldBegin\n");
  expect_refused((dir / "float_overflow.pbrt").string(), {"float_overflow.pbrt:1: Translate", "single precision"});
}

// NaN shading normals and uv in a PLY file are refused, as NaN positions are.
TEST_F(BadInput, PlyNanNormalsAndUvAreRefused) {
  expect_refused(input("ply_nan_normal.pbrt").string(), {"ply_nan_normal.pbrt:5", "nan_normal.ply", "vertex 1", "normal", "not finite"});
  expect_refused(input("ply_nan_uv.pbrt").string(), {"ply_nan_uv.pbrt:5", "nan_uv.ply", "vertex 1", "texture coordinate", "not finite"});
}

// An image whose header claims 100000 x 100000 pixels is refused from its
// header, before it is decoded; so is it for mcrt diff.
TEST_F(BadInput, HugeImageHeaderIsRefusedBeforeDecoding) {
  expect_refused(input("texture_huge_header.pbrt").string(), {"texture_huge_header.pbrt:6", "huge_header.png", "100000 x 100000"});
  const result d = run("diff " + input("huge_header.png").string() + " " + input("huge_header.png").string());
  EXPECT_EQ(d.status, 2) << d.err;
  EXPECT_NE(d.err.find("100000 x 100000"), std::string::npos) << d.err;
}

// Includes that never end: a file that includes itself through another,
// and a few files that include each other twice over (2^30 copies).
TEST_F(BadInput, IncludeCyclesAndFanOutAreRefused) {
  write("a.pbrt", "WorldBegin\nInclude \"b.pbrt\"\n");
  write("b.pbrt", "Include \"a.pbrt\"\n");
  expect_refused((dir / "a.pbrt").string(), {"b.pbrt:1: Include", "includes itself", "a.pbrt -> b.pbrt -> a.pbrt"});
  for (int i = 0; i < 30; ++i) {
    const std::string next = std::to_string(i + 1);
    std::string text = "Include \"f";  // (built by appending: GCC 12 flags "..." + to_string() falsely, bug 105329)
    text += next;
    text += ".pbrt\"\nInclude \"f";
    text += next;
    text += ".pbrt\"\n";
    std::string name = "f";
    name += std::to_string(i);
    name += ".pbrt";
    write(name, text);
  }
  write("f30.pbrt", "Identity\n");
  expect_refused((dir / "f0.pbrt").string(), {"Include", "more than"});
}
