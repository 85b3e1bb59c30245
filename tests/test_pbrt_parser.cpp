// The pbrt-v4 scene format's syntax (src/pbrt/): tokens, numbers in every
// form pbrt writes, directives and their arguments, parameter lists with and
// without brackets, every parameter type, Include and Import resolved against
// the top-level file's directory, gzip-compressed files; and bad input: each
// error one line that names the file and the line. A fuzz test feeds seeded
// mutations of a scene to the parser: it must return or throw parse_error,
// never crash, hang or throw anything else.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "mcrt/core/rng.hpp"
#include "pbrt/parser.hpp"

using namespace mcrt::pbrt;
namespace fs = std::filesystem;

namespace {

std::vector<directive> parse(const std::string& text) { return parse_text(text, "test.pbrt"); }

// The message of the parse_error that parsing `text` throws ("" if none).
std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const parse_error& e) {
    return e.what();
  }
  return "";
}

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = fs::temp_directory_path() / ("mcrt_pbrt_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = path / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  fs::path path;
};

// The scene the fuzz test mutates: every kind of directive and parameter.
const char* const sample_scene = R"(# a scene
LookAt 0 1 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 45 ]
Film "rgb" "integer xresolution" 64 "integer yresolution" [48] "string filename" "out.exr"
Sampler "zsobol" "integer pixelsamples" 16
Integrator "path" "integer maxdepth" 5
PixelFilter "gaussian" "float radius" 1.5
WorldBegin
Texture "checks" "spectrum" "checkerboard" "float uscale" 8 "rgb tex1" [1 1 1] "rgb tex2" [.1 .1 .1]
MakeNamedMaterial "floor" "string type" "diffuse" "texture reflectance" "checks"
AttributeBegin
  AreaLightSource "diffuse" "blackbody L" 6500 "float scale" 2 "bool twosided" true
  Translate 0 4 0
  Rotate 90 1 0 0
  Shape "disk" "float radius" 1
AttributeEnd
AttributeBegin
  NamedMaterial "floor"
  Transform [ 1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1 ]
  Shape "trianglemesh" "point3 P" [ -1 0 -1  1 0 -1  1 0 1  -1 0 1 ]
        "integer indices" [ 0 1 2  0 2 3 ] "point2 uv" [ 0 0 1 0 1 1 0 1 ]
        "normal N" [ 0 1 0  0 1 0  0 1 0  0 1 0 ]
AttributeEnd
Material "conductor" "spectrum eta" "metal-Cu-eta" "spectrum k" "metal-Cu-k" "float roughness" 0.1
Shape "sphere" "float radius" 0.5
)";

}  // namespace

TEST(PbrtParser, DirectivesArgumentsAndParameters) {
  const std::vector<directive> ds = parse(sample_scene);
  ASSERT_EQ(ds.size(), 22u);
  EXPECT_EQ(ds[0].name, "LookAt");
  EXPECT_EQ(ds[0].numbers, (std::vector<double>{0, 1, -5, 0, 0, 0, 0, 1, 0}));
  EXPECT_EQ(ds[0].loc.line, 2);
  EXPECT_EQ(ds[1].name, "Camera");
  EXPECT_EQ(ds[1].type, "perspective");
  ASSERT_NE(ds[1].find("fov"), nullptr);
  EXPECT_EQ(ds[1].find("fov")->numbers, std::vector<double>{45});
  // Brackets are optional around one value.
  EXPECT_EQ(ds[2].find("xresolution")->numbers, std::vector<double>{64});
  EXPECT_EQ(ds[2].find("yresolution")->numbers, std::vector<double>{48});
  EXPECT_EQ(ds[2].find("filename")->strings, std::vector<std::string>{"out.exr"});
  EXPECT_EQ(ds[6].name, "WorldBegin");
  EXPECT_EQ(ds[7].name, "Texture");
  EXPECT_EQ(ds[7].strings, (std::vector<std::string>{"checks", "spectrum", "checkerboard"}));
  EXPECT_EQ(ds[7].type, "checkerboard");
  EXPECT_EQ(ds[7].find("tex2")->numbers, (std::vector<double>{0.1, 0.1, 0.1}));
  EXPECT_EQ(ds[8].strings, std::vector<std::string>{"floor"});
  EXPECT_EQ(ds[8].find("reflectance")->type, "texture");
  const directive& light = ds[10];
  EXPECT_EQ(light.name, "AreaLightSource");
  EXPECT_EQ(light.find("L")->type, "blackbody");
  EXPECT_EQ(light.find("twosided")->bools, std::vector<bool>{true});
  EXPECT_EQ(ds[12].numbers, (std::vector<double>{90, 1, 0, 0}));
  EXPECT_EQ(ds[17].numbers.size(), 16u);
  const directive& mesh = ds[18];
  EXPECT_EQ(mesh.type, "trianglemesh");
  EXPECT_EQ(mesh.find("P")->numbers.size(), 12u);
  EXPECT_EQ(mesh.find("indices")->numbers, (std::vector<double>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(mesh.find("N")->type, "normal");
  EXPECT_EQ(mesh.loc.line, 20);
  EXPECT_EQ(mesh.find("uv")->loc.line, 21);
  EXPECT_EQ(ds[20].find("eta")->strings, std::vector<std::string>{"metal-Cu-eta"});
  EXPECT_EQ(ds[19].name, "AttributeEnd");
  EXPECT_EQ(ds[21].type, "sphere");
}

TEST(PbrtParser, NumbersInEveryFormPbrtWrites) {
  const auto ds = parse(R"(Shape "x" "float v" [ 1 -2 +3 .5 -.25 5. 1e3 -2.5E-2 +1e+2 0 ])");
  EXPECT_EQ(ds[0].find("v")->numbers, (std::vector<double>{1, -2, 3, 0.5, -0.25, 5, 1000, -0.025, 100, 0}));
  for (const char* bad : {"1x", "--1", "+-1", "1e", ".", "e3", "0x10", "1,5"})
    EXPECT_NE(error_of(std::string("Shape \"x\" \"float v\" [ ") + bad + " ]").find("is not a number"),
              std::string::npos)
        << bad;
  for (const char* nonfinite : {"1e999", "-1e999", "-inf", "-nan"})
    EXPECT_NE(error_of(std::string("Translate ") + nonfinite + " 0 0").find("not a finite number"), std::string::npos)
        << nonfinite;
}

TEST(PbrtParser, StringsCommentsAndBooleans) {
  const auto ds = parse("# comment \"not a string\"\n"
                        "Shape \"x\" # trailing\n"
                        "  \"string s\" \"a \\\"quoted\\\" \\\\ word\\n\" # another\n"
                        "  \"bool b\" [ \"true\" false ]\n");
  ASSERT_EQ(ds.size(), 1u);
  EXPECT_EQ(ds[0].find("s")->strings, std::vector<std::string>{"a \"quoted\" \\ word\n"});
  EXPECT_EQ(ds[0].find("b")->bools, (std::vector<bool>{true, false}));
  EXPECT_EQ(ds[0].find("b")->loc.line, 4);
}

TEST(PbrtParser, ParameterTypesAndCounts) {
  const auto ds = parse(R"(Shape "x" "point2 a" [1 2] "vector2 b" [1 2 3 4] "point3 c" [1 2 3] "vector3 d" [1 2 3]
    "normal3 e" [0 0 1] "point f" [1 2 3] "vector g" [1 2 3] "color h" [1 2 3] "spectrum i" [300 1 800 2]
    "spectrum j" "glass-BK7" "texture k" "tex" "integer l" [-3 7])");
  EXPECT_EQ(ds[0].params.size(), 12u);
  EXPECT_EQ(ds[0].find("i")->numbers.size(), 4u);
  EXPECT_EQ(ds[0].find("l")->numbers, (std::vector<double>{-3, 7}));
  const std::pair<const char*, const char*> bad[] = {
      {R"(Shape "x" "rgb L" [1 2])", "expected 3 values"},
      {R"(Shape "x" "point3 P" [1 2 3 4])", "multiple of 3"},
      {R"(Shape "x" "point2 uv" [1 2 3])", "multiple of 2"},
      {R"(Shape "x" "blackbody L" [6500 1])", "expected 1 values"},
      {R"(Shape "x" "spectrum s" [300 1 800])", "(wavelength, value) pairs"},
      {R"(Shape "x" "integer n" 1.5)", "not an integer"},
      {R"(Shape "x" "bool b" yes)", "expected true or false"},
      {R"(Shape "x" "string s" 3)", "expected quoted strings"},
      {R"(Shape "x" "float f" "3")", "expected a number"},
      {R"(Shape "x" "quaternion q" [1 0 0 0])", "unknown type 'quaternion'"},
      {R"(Shape "x" "float" 1)", "expected a parameter \"TYPE NAME\""},
      {R"(Shape "x" "float a b" 1)", "expected a parameter \"TYPE NAME\""},
      {R"(Shape "x" "float r" [])", "no values"},
      {R"(Shape "x" "float r" 1 "float r" 2)", "given twice"},
      {R"(Shape "x" "float r" [ 1 2)", "no closing ']'"},
  };
  for (const auto& [text, needle] : bad) {
    const std::string e = error_of(text);
    EXPECT_EQ(e.rfind("test.pbrt:1: ", 0), 0u) << text << " -> " << e;
    EXPECT_NE(e.find(needle), std::string::npos) << text << " -> " << e;
  }
}

TEST(PbrtParser, BadSyntaxNamesTheFileAndTheLine) {
  const std::pair<const char*, const char*> bad[] = {
      {"WorldBegin\n\nShape \"sphere\" \"string s\" \"unterminated", "test.pbrt:3: unterminated string"},
      {"WorldBegin\nShape \"x\" \"string s\" \"runs\nover\"", "test.pbrt:2: unterminated string"},
      {"Shape \"x\" \"string s\" \"bad \\q escape\"", "test.pbrt:1: unknown escape"},
      {"WorldBegin\nFrobnicate 1 2", "test.pbrt:2: unknown directive 'Frobnicate'"},
      {"Translate 1 2", "test.pbrt:1: Translate (3 numbers): expected a number, got the end of the file"},
      {"Rotate 90 0 1 x", "test.pbrt:1: Rotate (4 numbers): 'x' is not a number"},
      {"Transform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0]", "test.pbrt:1: Transform (16 numbers in brackets): got 15"},
      {"ConcatTransform 1 0 0 0", "expected '['"},
      {"Shape sphere", "test.pbrt:1: Shape (its type): expected a quoted string, got 'sphere'"},
      {"\"float x\" 1", "test.pbrt:1: expected a directive, got the string"},
      {"[ 1 ]", "expected a directive, got '['"},
      {"ActiveTransform Sometimes", "expected All, StartTime or EndTime"},
      {"AttributeBegin\nAttributeEnd\nAttributeEnd", "test.pbrt:3: AttributeEnd without a matching AttributeBegin"},
      {"\n\nAttributeBegin\nShape \"sphere\"", "test.pbrt:3: AttributeBegin without its matching end"},
      {"AttributeBegin\nTransformEnd", "test.pbrt:2: TransformEnd closes the AttributeBegin of line 1"},
      {"Include \"no/such/file.pbrt\"", "test.pbrt:1: 'no/such/file.pbrt': no such file"},
  };
  for (const auto& [text, needle] : bad) {
    const std::string e = error_of(text);
    EXPECT_NE(e.find(needle), std::string::npos) << text << " -> " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << "one line: " << e;
  }
}

TEST(PbrtParser, IncludeAndImportResolveAgainstTheTopLevelDirectory) {
  TempDir dir;
  // The nested include names its file relative to the top-level file's
  // directory (as pbrt-v4), not to the including file's.
  dir.write("parts/a.pbrt", "Translate 1 2 3\nInclude \"parts/b.pbrt\"\n");
  dir.write("parts/b.pbrt", "AttributeBegin\nShape \"sphere\"\n");
  dir.write("parts/c.pbrt", "MakeNamedMaterial \"m\" \"string type\" \"diffuse\"\n");
  const fs::path top = dir.write("scene.pbrt", "WorldBegin\nImport \"parts/c.pbrt\"\nInclude \"parts/a.pbrt\"\nAttributeEnd\n");
  const std::vector<directive> ds = parse_file(top.string());
  ASSERT_EQ(ds.size(), 6u);
  EXPECT_EQ(ds[1].name, "MakeNamedMaterial");
  EXPECT_EQ(ds[2].name, "Translate");
  EXPECT_EQ(ds[3].name, "AttributeBegin");  // opened in b.pbrt ...
  EXPECT_EQ(ds[5].name, "AttributeEnd");    // ... closed in the top-level file
  EXPECT_NE(ds[4].loc.str().find("b.pbrt:2"), std::string::npos) << ds[4].loc.str();
  EXPECT_NE(ds[2].loc.str().find("a.pbrt:1"), std::string::npos);
  // An error inside an included file names that file and line.
  dir.write("parts/bad.pbrt", "Shape \"sphere\"\n  \"float radius\" [ 1 \n");
  const fs::path top2 = dir.write("scene2.pbrt", "WorldBegin\nInclude \"parts/bad.pbrt\"\n");
  try {
    parse_file(top2.string());
    FAIL() << "no error";
  } catch (const parse_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.pbrt:2: parameter \"float radius\": no closing ']'"), std::string::npos)
        << e.what();
  }
  // A file that includes itself.
  const fs::path loop = dir.write("loop.pbrt", "Include \"loop.pbrt\"\n");
  try {
    parse_file(loop.string());
    FAIL() << "no error";
  } catch (const parse_error& e) {
    EXPECT_NE(std::string(e.what()).find("loop.pbrt:1: Include: 'loop.pbrt' includes itself (loop.pbrt -> loop.pbrt)"),
              std::string::npos)
        << e.what();
  }
  // A chain of distinct files deeper than the bound.
  for (int i = 0; i < 70; ++i)
    dir.write("chain/" + std::to_string(i) + ".pbrt", "Include \"chain/" + std::to_string(i + 1) + ".pbrt\"\n");
  dir.write("chain/70.pbrt", "Identity\n");
  try {
    parse_file(dir.write("chain.pbrt", "Include \"chain/0.pbrt\"\n").string());
    FAIL() << "no error";
  } catch (const parse_error& e) {
    EXPECT_NE(std::string(e.what()).find("nested deeper than 64"), std::string::npos) << e.what();
  }
}

TEST(PbrtParser, ReadsGzipCompressedFiles) {
  TempDir dir;
  const fs::path gz = dir.path / "scene.pbrt.gz";
  const std::string text = sample_scene;
  gzFile f = gzopen(gz.string().c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(gzwrite(f, text.data(), static_cast<unsigned>(text.size())), static_cast<int>(text.size()));
  ASSERT_EQ(gzclose(f), Z_OK);
  EXPECT_EQ(parse_file(gz.string()).size(), parse(text).size());
  // A truncated gzip file is refused.
  std::string bytes;
  {
    std::ifstream in(gz, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const fs::path cut = dir.write("cut.pbrt.gz", bytes.substr(0, bytes.size() / 2));
  try {
    parse_file(cut.string());
    FAIL() << "no error";
  } catch (const parse_error& e) {
    EXPECT_NE(std::string(e.what()).find("gzip"), std::string::npos) << e.what();
  }
}

// Seeded mutations of the sample scene (bytes replaced, inserted, deleted,
// duplicated runs, brackets and quotes), 100000 inputs: parsing returns or
// throws parse_error, whose message is one line naming "fuzz.pbrt:".
TEST(PbrtParser, FuzzedInputsGiveDirectivesOrOneLineErrors) {
  mcrt::pcg32 rng(2030, 7);
  const std::string base = sample_scene;
  const char alphabet[] = "[]\"#\\ \n0123456789.-+eE abcxyzAttributeBeginEndShape\"float\t";
  int parsed = 0, refused = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 100000; ++i) {
    std::string s = base;
    const int edits = 1 + static_cast<int>(rng.uniform() * 6);
    for (int k = 0; k < edits && !s.empty(); ++k) {
      const std::size_t at = static_cast<std::size_t>(rng.uniform() * static_cast<float>(s.size()));
      const char c = alphabet[static_cast<std::size_t>(rng.uniform() * (sizeof alphabet - 1))];
      switch (static_cast<int>(rng.uniform() * 5)) {
        case 0: s[at] = c; break;
        case 1: s.insert(s.begin() + static_cast<std::ptrdiff_t>(at), c); break;
        case 2: s.erase(at, 1 + static_cast<std::size_t>(rng.uniform() * 8)); break;
        case 3: s.insert(at, s.substr(at, static_cast<std::size_t>(rng.uniform() * 40))); break;
        default: s.resize(at); break;
      }
    }
    try {
      parse_text(s, "fuzz.pbrt");
      ++parsed;
    } catch (const parse_error& e) {
      const std::string what = e.what();
      ASSERT_EQ(what.rfind("fuzz.pbrt:", 0), 0u) << what;
      ASSERT_EQ(what.find('\n'), std::string::npos) << what;
      ++refused;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("fuzz: %d inputs parsed, %d refused, %.2f s\n", parsed, refused, seconds);
  EXPECT_GT(parsed, 1000);
  EXPECT_GT(refused, 10000);
}
