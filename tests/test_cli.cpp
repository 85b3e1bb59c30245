// The mcrt executable against its contract (docs/cli.md and
// scenes/FORMAT.md): outputs, stats, diff, determinism across thread counts,
// and bad input: one line naming the file and the place, exit status 2, no
// output file created or touched.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

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

class Cli : public ::testing::Test {
 protected:
  fs::path dir;

  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir = fs::temp_directory_path() / ("mcrt_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  result run(const std::string& args) const {
    const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    const std::string cmd = std::string(MCRT_EXE) + " " + args + " >" + out.string() + " 2>" + err.string() + " </dev/null";
    const int raw = std::system(cmd.c_str());
    result r{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
    fs::remove(out);
    fs::remove(err);
    return r;
  }

  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = dir / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

  // A small valid scene with `objects` spliced in.
  std::string scene_with(const std::string& objects, const std::string& extra_materials = "") const {
    return R"({
  "camera": {"lookfrom": [0, 1, -3], "lookat": [0, 0.5, 0], "vup": [0, 1, 0], "vfov": 40, "width": 16, "height": 12},
  "render": {"spp": 2, "max_depth": 4},
  "materials": {"white": {"type": "lambertian", "albedo": [0.7, 0.7, 0.7]},
                "light": {"type": "diffuse_light", "emit": [4, 4, 4]})" +
           extra_materials + R"(},
  "objects": [)" + objects + "]}";
  }

  static std::string good_objects() {
    return R"({"type": "xz_rect", "x0": -5, "x1": 5, "z0": -5, "z1": 5, "k": 0, "material": "white"},
              {"type": "xz_rect", "x0": -0.5, "x1": 0.5, "z0": -0.5, "z1": 0.5, "k": 2, "material": "light", "flip": true},
              {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "white"})";
  }

  // Runs a failing render and checks the contract for bad input: exit 2,
  // one line on stderr that contains every `needles`, nothing on stdout, and
  // the output file (which exists beforehand) left byte for byte as it was.
  void expect_bad(const std::string& args, std::initializer_list<std::string> needles, const fs::path& out) const {
    std::ofstream(out, std::ios::binary) << "previous contents";
    const result r = run(args);
    EXPECT_EQ(r.status, 2) << args << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line expected, got: " << r.err;
    for (const auto& n : needles) EXPECT_NE(r.err.find(n), std::string::npos) << "'" << n << "' not in: " << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_EQ(slurp(out), "previous contents") << "the output file was touched";
    for (const auto& e : fs::directory_iterator(out.parent_path()))
      EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "temporary left: " << e.path();
  }

  void expect_bad_scene(const std::string& scene_text, std::initializer_list<std::string> needles) const {
    const fs::path s = write("bad.json", scene_text), out = dir / "out.exr";
    std::vector<std::string> all{"bad.json"};
    all.insert(all.end(), needles.begin(), needles.end());
    std::ofstream(out) << "previous contents";
    const result r = run("render " + s.string() + " -o " + out.string() + " --quiet");
    EXPECT_EQ(r.status, 2) << scene_text << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line expected, got: " << r.err;
    for (const auto& n : all) EXPECT_NE(r.err.find(n), std::string::npos) << "'" << n << "' not in: " << r.err;
    EXPECT_EQ(slurp(out), "previous contents");
  }
};

}  // namespace

TEST_F(Cli, RendersEveryFormatWithStats) {
  const fs::path s = write("good.json", scene_with(good_objects()));
  for (const std::string ext : {"exr", "png", "ppm"}) {
    const fs::path out = dir / ("img." + ext), stats = dir / ("stats_" + ext + ".json");
    const result r = run("render " + s.string() + " -o " + out.string() + " --stats=" + stats.string() + " --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << "--quiet: " << r.err;
    EXPECT_TRUE(r.out.empty()) << "nothing but requested data on stdout: " << r.out;
    ASSERT_TRUE(fs::exists(out));
    const auto j = nlohmann::json::parse(slurp(stats));
    for (const char* key : {"render_seconds", "spp", "width", "height", "threads", "samples_per_second", "light_sampling",
                            "integrator", "sampler"})
      EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_EQ(j["spp"], 2);
    EXPECT_EQ(j["width"], 16);
    EXPECT_EQ(j["height"], 12);
    EXPECT_EQ(j["light_sampling"], "area");
    EXPECT_EQ(j["integrator"], "mis") << "the default integrator (contract cli.md)";
    EXPECT_EQ(j["sampler"], "sobol");
    EXPECT_NEAR(j["samples_per_second"].get<double>(), 16.0 * 12 * 2 / j["render_seconds"].get<double>(), 1e-6 * j["samples_per_second"].get<double>());
  }
  // EXR header attributes: render time and spp (attribute names are plain text in the header).
  const std::string exr = slurp(dir / "img.exr");
  EXPECT_NE(exr.find("mcrt:render_seconds"), std::string::npos);
  EXPECT_NE(exr.find("mcrt:spp"), std::string::npos);
  // PPM: Shirley's plain format.
  EXPECT_EQ(slurp(dir / "img.ppm").rfind("P3\n16 12\n255\n", 0), 0u);
}

TEST_F(Cli, VersionPrintsTheProjectVersion) {
  const result r = run("--version");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, std::string("mcrt ") + MCRT_VERSION + "\n");
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(Cli, FlagsOverrideTheScene) {
  const fs::path s = write("good.json", scene_with(good_objects())), stats = dir / "s.json";
  const result r = run("render " + s.string() + " -o " + (dir / "o.exr").string() +
                       " --spp 3 --width=20 --height 10 --max-depth 2 --threads 1 --seed 9 --light-sampling area --stats " +
                       stats.string() + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(stats));
  EXPECT_EQ(j["spp"], 3);
  EXPECT_EQ(j["width"], 20);
  EXPECT_EQ(j["height"], 10);
  EXPECT_EQ(j["threads"], 1);
}

TEST_F(Cli, DefaultOutputIsSceneNameExrInTheWorkingDirectory) {
  const fs::path s = write("my_scene.json", scene_with(good_objects()));
  const result r = run("render " + s.string() + " --quiet --spp 1 && mv my_scene.exr " + (dir / "moved.exr").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "moved.exr"));
}

TEST_F(Cli, ProgressGoesToStderrUnlessQuiet) {
  const fs::path s = write("good.json", scene_with(good_objects()));
  const result r = run("render " + s.string() + " -o " + (dir / "o.png").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("100.0%"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
  // To a file (not a terminal): no carriage returns, a line per report of
  // at most one per tenth of the image (and one per 30 s), ending at 100 %.
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  const auto lines = std::count(r.err.begin(), r.err.end(), '\n');
  EXPECT_GE(lines, 1);
  EXPECT_LE(lines, 11) << r.err;
  EXPECT_NE(r.err.rfind("rendering 100.0%"), std::string::npos);
  EXPECT_EQ(r.err.back(), '\n');
}

// Every integrator with every sample generator: the same image for any
// thread count, --stats naming both, and direct light only (--max-depth 1).
TEST_F(Cli, EveryIntegratorAndSamplerIsDeterministicAcrossThreads) {
  const fs::path s = write("good.json", scene_with(good_objects()));
  int combo = 0;
  for (const char* integrator : {"mixture", "nee", "mis"})
    for (const char* sampler : {"independent", "stratified", "sobol"}) {
        const char* depth = combo++ % 2 ? "1" : "4";
        const std::string flags = std::string(" --integrator ") + integrator + " --sampler=" + sampler + " --max-depth " + depth +
                                  " --seed 3 --spp 5 --quiet";
        const fs::path a = dir / "a.exr", b = dir / "b.exr", stats = dir / "s.json";
        ASSERT_EQ(run("render " + s.string() + " -o " + a.string() + " --threads 1 --stats " + stats.string() + flags).status, 0);
        ASSERT_EQ(run("render " + s.string() + " -o " + b.string() + " --threads 3" + flags).status, 0);
        const result r = run("diff " + a.string() + " " + b.string() + " --json");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(nlohmann::json::parse(r.out)["mse"].get<double>(), 0.0) << flags;
        const auto j = nlohmann::json::parse(slurp(stats));
        EXPECT_EQ(j["integrator"], integrator);
        EXPECT_EQ(j["sampler"], sampler);
        EXPECT_EQ(j["max_depth"], std::stoi(depth));
      }
}

TEST_F(Cli, SameSeedSameImageForAnyThreadCountAndDiffReportsZero) {
  const fs::path s = write("good.json", scene_with(good_objects()));
  const fs::path a = dir / "a.exr", b = dir / "b.exr", c = dir / "c.exr";
  ASSERT_EQ(run("render " + s.string() + " -o " + a.string() + " --threads 1 --seed 5 --quiet").status, 0);
  ASSERT_EQ(run("render " + s.string() + " -o " + b.string() + " --threads 2 --seed 5 --quiet").status, 0);
  ASSERT_EQ(run("render " + s.string() + " -o " + c.string() + " --threads 2 --seed 6 --quiet").status, 0);
  result r = run("diff " + a.string() + " " + b.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["rmse"].get<double>(), 0.0);
  EXPECT_EQ(j["mse"].get<double>(), 0.0);
  EXPECT_EQ(j["relmse"].get<double>(), 0.0);
  EXPECT_EQ(j["mean_diff_percent"].get<double>(), 0.0);
  r = run("diff " + a.string() + " " + c.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["rmse"].get<double>(), 0.0);
  EXPECT_NEAR(j["rmse"].get<double>() * j["rmse"].get<double>(), j["mse"].get<double>(), 1e-12);
  r = run("diff " + a.string() + " " + c.string());
  ASSERT_EQ(r.status, 0);
  for (const char* key : {"rmse", "mse", "relmse", "mean_diff_percent"}) EXPECT_NE(r.out.find(key), std::string::npos);
}

TEST_F(Cli, DiffRefusesImagesOfDifferentSize) {
  const fs::path s = write("good.json", scene_with(good_objects()));
  const fs::path a = dir / "a.exr", b = dir / "b.exr";
  ASSERT_EQ(run("render " + s.string() + " -o " + a.string() + " --quiet").status, 0);
  ASSERT_EQ(run("render " + s.string() + " -o " + b.string() + " --width 8 --quiet").status, 0);
  const result r = run("diff " + a.string() + " " + b.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("size"), std::string::npos) << r.err;
  EXPECT_EQ(run("diff " + a.string() + " " + (dir / "missing.exr").string()).status, 2);
}

TEST_F(Cli, BadCommandLines) {
  const fs::path s = write("good.json", scene_with(good_objects())), out = dir / "out.exr";
  const std::string base = "render " + s.string() + " -o " + out.string() + " --quiet ";
  expect_bad(base + "--spp 0", {"--spp"}, out);
  expect_bad(base + "--spp -3", {"--spp"}, out);
  expect_bad(base + "--width 20000", {"--width", "16384"}, out);
  expect_bad(base + "--threads 0", {"--threads"}, out);
  expect_bad(base + "--light-sampling sideways", {"--light-sampling"}, out);
  expect_bad(base + "--ellipse-map round", {"--ellipse-map"}, out);
  expect_bad(base + "--integrator bidir", {"--integrator"}, out);
  expect_bad(base + "--integrator", {"--integrator"}, out);
  expect_bad(base + "--sampler halton", {"--sampler"}, out);
  expect_bad(base + "--mis-heuristic maximum", {"--mis-heuristic"}, out);
  expect_bad(base + "--light-select random", {"--light-select"}, out);
  expect_bad(base + "--no-such-flag", {"no-such-flag"}, out);
  expect_bad("render " + (dir / "missing.json").string() + " -o " + out.string(), {"missing.json"}, out);
  expect_bad("frobnicate", {"frobnicate"}, out);
}

TEST_F(Cli, BadOutputPaths) {
  const fs::path s = write("good.json", scene_with(good_objects())), out = dir / "out.exr";
  const std::string base = "render " + s.string() + " --quiet ";
  expect_bad(base + "-o " + (dir / "out.tiff").string(), {"out.tiff", ".tiff"}, out);
  expect_bad(base + "-o " + (dir / "no_such_dir" / "x.exr").string(), {"no_such_dir"}, out);
  expect_bad(base + "-o " + out.string() + " --stats " + (dir / "no_such_dir" / "s.json").string(), {"no_such_dir"}, out);
  EXPECT_FALSE(fs::exists(dir / "out.tiff"));
  if (::geteuid() != 0) {  // root may write anywhere
    fs::create_directories(dir / "ro");
    fs::permissions(dir / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    expect_bad(base + "-o " + (dir / "ro" / "x.exr").string(), {"ro"}, out);
    fs::permissions(dir / "ro", fs::perms::owner_all);
  }
}

TEST_F(Cli, BadScenes) {
  const std::string floor = R"({"type": "xz_rect", "x0": -5, "x1": 5, "z0": -5, "z1": 5, "k": 0, "material": "white"})";
  expect_bad_scene("{ \"camera\": ", {"invalid JSON"});
  expect_bad_scene("[1, 2]", {"top level"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "torus", "material": "white"})"), {"objects[1].type", "torus"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1, 0], "material": "white"})"),
                   {"objects[1].radius", "missing"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1, 0], "radius": "big", "material": "white"})"),
                   {"objects[1].radius", "number"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1], "radius": 1, "material": "white"})"),
                   {"objects[1].center", "3"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1, 0], "radius": 0, "material": "white"})"),
                   {"objects[1].radius", "> 0"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1, 0], "radius": -2, "material": "white"})"),
                   {"objects[1].radius", "> 0"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "chrome"})"),
                   {"objects[1].material", "chrome"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1e999, 0], "radius": 1, "material": "white"})"),
                   {"objects[1].center", "finite"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "xz_rect", "x0": 1, "x1": 1, "z0": 0, "z1": 1, "k": 2, "material": "light"})"),
                   {"objects[1]", "zero-area"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "ellipse", "center": [0, 2, 0], "axis1": [1, 0, 0], "axis2": [0, 0, 0], "material": "light"})"),
                   {"objects[1].axis2", "degenerate"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "rect", "corner": [0, 2, 0], "edge1": [1, 0, 0], "edge2": [1, 0, 1], "material": "light"})"),
                   {"objects[1]", "orthogonal"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "white", "flipp": true})"),
                   {"objects[1].flipp", "unknown field"});
  expect_bad_scene(scene_with(floor, R"(, "odd": {"type": "plasma"})"), {"materials.odd.type", "plasma"});
  expect_bad_scene(scene_with(floor, R"(, "m": {"type": "metal", "albedo": [1, 1, 1], "fuzz": 2})"), {"materials.m.fuzz"});
  expect_bad_scene(scene_with(floor, R"(, "g": {"type": "dielectric", "ior": 0})"), {"materials.g.ior"});
  // An albedo above 1 creates light (1e38 overflowed a path's throughput).
  expect_bad_scene(scene_with(floor, R"(, "w": {"type": "lambertian", "albedo": [0.5, 1e38, 0.5]})"),
                   {"materials.w.albedo", "[0, 1]"});
  expect_bad_scene(scene_with(floor, R"(, "m": {"type": "metal", "albedo": [1.5, 1, 1], "fuzz": 0})"),
                   {"materials.m.albedo", "[0, 1]"});
  // Finite as a double, infinite as the float every value becomes.
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1e39, 0], "radius": 1, "material": "white"})"),
                   {"objects[1].center", "single precision"});
  std::string big = scene_with(floor);
  big.replace(big.find("\"width\": 16"), 11, "\"width\": 99999");
  expect_bad_scene(big, {"camera.width", "16384"});
  std::string zero_spp = scene_with(floor);
  zero_spp.replace(zero_spp.find("\"spp\": 2"), 8, "\"spp\": 0");
  expect_bad_scene(zero_spp, {"render.spp"});
  std::string no_camera = scene_with(floor);
  no_camera.replace(no_camera.find("\"camera\""), 8, "\"kamera\"");
  expect_bad_scene(no_camera, {"kamera"});
}

// The per-light "sampling" field of the scene format; --light-sampling
// overrides it. Strategies this build lacks are refused as such.
TEST_F(Cli, PerLightSamplingField) {
  const std::string floor = R"({"type": "xz_rect", "x0": -5, "x1": 5, "z0": -5, "z1": 5, "k": 0, "material": "white"})";
  const std::string lamp = R"({"type": "xz_rect", "x0": -0.5, "x1": 0.5, "z0": -0.5, "z1": 0.5, "k": 2, "material": "light", "flip": true)";
  const fs::path s = write("lamp.json", scene_with(floor + ", " + lamp + R"(, "sampling": "solid-angle"})"));
  const fs::path out = dir / "o.exr", stats = dir / "s.json";
  ASSERT_EQ(run("render " + s.string() + " -o " + out.string() + " --stats " + stats.string() + " --quiet").status, 0);
  EXPECT_EQ(nlohmann::json::parse(slurp(stats))["light_sampling"], "solid-angle");
  ASSERT_EQ(run("render " + s.string() + " -o " + out.string() + " --light-sampling area --stats " + stats.string() + " --quiet").status, 0);
  EXPECT_EQ(nlohmann::json::parse(slurp(stats))["light_sampling"], "area");
  expect_bad_scene(scene_with(floor + ", " + lamp + R"(, "sampling": "sideways"})"), {"objects[1].sampling", "sideways"});
  for (const char* strategy : {"projected-solid-angle", "bilinear-solid-angle", "auto"}) {
    const fs::path c = write("lamp_c.json", scene_with(floor + ", " + lamp + R"(, "sampling": ")" + strategy + R"("})"));
    ASSERT_EQ(run("render " + c.string() + " -o " + out.string() + " --stats " + stats.string() + " --quiet").status, 0) << strategy;
    EXPECT_EQ(nlohmann::json::parse(slurp(stats))["light_sampling"], strategy);
  }
  // A sphere light without the field keeps its cone (solid angle); with it, its own strategy.
  const std::string ball = R"({"type": "sphere", "center": [0, 2, 0], "radius": 0.5, "material": "light")";
  for (const auto& [field, used] : {std::pair{"", "solid-angle"}, {R"(, "sampling": "area")", "area"},
                                    {R"(, "sampling": "projected-solid-angle")", "projected-solid-angle"},
                                    {R"(, "sampling": "bilinear-solid-angle")", "projected-solid-angle"},
                                    {R"(, "sampling": "auto")", "auto"}}) {
    const fs::path b = write("ball.json", scene_with(floor + ", " + ball + field + "}"));
    ASSERT_EQ(run("render " + b.string() + " -o " + out.string() + " --stats " + stats.string() + " --quiet").status, 0) << field;
    EXPECT_EQ(nlohmann::json::parse(slurp(stats))["light_sampling"], used) << field;
  }
  expect_bad_scene(scene_with(floor + R"(, {"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "white", "sampling": "area"})"),
                   {"objects[1].sampling", "only a light"});
  expect_bad_scene(scene_with(floor + R"(, {"type": "xz_rect_sa", "x0": -1, "x1": 1, "z0": -1, "z1": 1, "k": 2, "material": "light", "sampling": "area"})"),
                   {"objects[1].sampling", "contradicts"});
  ASSERT_EQ(run("render " + s.string() + " -o " + out.string() + " --light-sampling auto --stats " + stats.string() + " --quiet").status, 0);
  EXPECT_EQ(nlohmann::json::parse(slurp(stats))["light_sampling"], "auto");
}

// `auto` measures the image's noise by a pilot unless --auto-rest-variance
// fixes v_rest; the stats say so, and its time is part of render_seconds,
// as is the set-up of the lights `auto` samples (auto_setup_seconds, with
// and without the pilot; absent where no light is sampled by `auto`).
TEST_F(Cli, AutoNoisePilotInStats) {
  const std::string floor = R"({"type": "xz_rect", "x0": -5, "x1": 5, "z0": -5, "z1": 5, "k": 0, "material": "white"})";
  const std::string lamp = R"({"type": "xz_rect", "x0": -0.5, "x1": 0.5, "z0": -0.5, "z1": 0.5, "k": 2, "material": "light", "flip": true})";
  const fs::path s = write("lamp.json", scene_with(floor + ", " + lamp));
  const fs::path out = dir / "o.exr", stats = dir / "s.json";
  const std::string base = "render " + s.string() + " -o " + out.string() + " --stats " + stats.string() + " --quiet ";
  ASSERT_EQ(run(base + "--light-sampling auto").status, 0);
  auto j = nlohmann::json::parse(slurp(stats));
  ASSERT_TRUE(j.contains("auto_pilot_seconds"));
  ASSERT_TRUE(j.contains("auto_image_variance"));
  ASSERT_TRUE(j.contains("auto_albedo"));
  EXPECT_NEAR(j["auto_albedo"].get<double>(), 0.7, 1e-6);  // scene_with's white floor
  EXPECT_GT(j["auto_image_variance"].get<double>(), 0.0);
  ASSERT_TRUE(j.contains("auto_setup_seconds"));
  EXPECT_GT(j["auto_setup_seconds"].get<double>(), 0.0);
  EXPECT_LE(j["auto_pilot_seconds"].get<double>() + j["auto_setup_seconds"].get<double>(),
            j["render_seconds"].get<double>());
  // The pilot's parts add up to its time, each one's measured (> 0).
  ASSERT_TRUE(j.contains("auto_pilot_parts_seconds"));
  double parts = 0.0;
  for (const char* part : {"noise", "emission", "settle"}) {
    ASSERT_TRUE(j["auto_pilot_parts_seconds"].contains(part)) << part;
    EXPECT_GT(j["auto_pilot_parts_seconds"][part].get<double>(), 0.0) << part;
    parts += j["auto_pilot_parts_seconds"][part].get<double>();
  }
  EXPECT_NEAR(parts, j["auto_pilot_seconds"].get<double>(), 1e-12 * parts);
  ASSERT_EQ(j["auto_lights"].size(), 1u);
  EXPECT_GE(j["auto_lights"][0]["fixed_point_steps"].get<int>(), 0);
  // mis: R from the low-variance pilot, run within the settling.
  EXPECT_GT(j["auto_lights"][0]["rest_pilot_seconds"].get<double>(), 0.0);
  EXPECT_LT(j["auto_lights"][0]["rest_pilot_seconds"].get<double>(),
            j["auto_pilot_parts_seconds"]["settle"].get<double>());
  // The emission term with the image's samples (no emitter in view here:
  // no edge pixels, kappa_E = 1), and with independent samples kappa_E = 1.
  for (const char* sampler : {"sobol", "independent"}) {
    ASSERT_EQ(run(base + "--light-sampling auto --sampler " + sampler).status, 0) << sampler;
    j = nlohmann::json::parse(slurp(stats));
    ASSERT_TRUE(j.contains("auto_edge_noise_factor") && j.contains("auto_image_variance_edges")) << sampler;
    EXPECT_EQ(j["auto_edge_noise_factor"].get<double>(), 1.0) << sampler;
    EXPECT_GE(j["auto_image_variance_edges"].get<double>(), 0.0) << sampler;
    EXPECT_LE(j["auto_image_variance_edges"].get<double>(), j["auto_image_variance"].get<double>()) << sampler;
  }
  for (const char* flags : {"--light-sampling auto --auto-rest-variance 4", "--light-sampling area", ""}) {
    ASSERT_EQ(run(base + flags).status, 0) << flags;
    j = nlohmann::json::parse(slurp(stats));
    EXPECT_FALSE(j.contains("auto_pilot_seconds")) << flags;
    const bool is_auto = std::string(flags).find("auto") != std::string::npos;
    EXPECT_EQ(j.contains("auto_setup_seconds"), is_auto) << flags;
    if (is_auto) {
      EXPECT_LE(j["auto_setup_seconds"].get<double>(), j["render_seconds"].get<double>()) << flags;
    }
  }
  expect_bad("render " + s.string() + " -o " + out.string() + " --light-sampling auto --auto-rest-variance 0",
             {"--auto-rest-variance"}, out);
}

// `auto` weighs its choice against its own cost at the pilot's receivers:
// a small lamp far above the floor gains nothing from a choice per light
// sample, and is sampled by area everywhere (the image bit for bit area
// sampling's, the stats still naming auto); a large lamp low over the
// floor keeps its choice (an image unlike area sampling's).
TEST_F(Cli, AutoTakesTheCheapestStrategyWhereItsChoiceDoesNotPay) {
  const std::string floor = R"({"type": "xz_rect", "x0": -5, "x1": 5, "z0": -5, "z1": 5, "k": 0, "material": "white"})";
  const fs::path out = dir / "o.exr", area = dir / "area.exr", stats = dir / "s.json";
  const auto diff_mse = [&] {
    const result r = run("diff " + out.string() + " " + area.string() + " --json");
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(r.out)["mse"].get<double>();
  };
  struct lamp_case {
    const char* lamp;
    int cheapest;
  };
  for (const lamp_case c : {lamp_case{R"("x0": -0.05, "x1": 0.05, "z0": -0.05, "z1": 0.05, "k": 4)", 1},
                            lamp_case{R"("x0": -1.5, "x1": 1.5, "z0": -1.5, "z1": 1.5, "k": 0.3)", 0}}) {
    const std::string lamp = std::string(R"({"type": "xz_rect", )") + c.lamp + R"(, "material": "light", "flip": true})";
    const fs::path s = write("lamp.json", scene_with(floor + ", " + lamp));
    const std::string base = "render " + s.string() + " --spp 16 --quiet --seed 3 ";
    ASSERT_EQ(run(base + "-o " + area.string() + " --light-sampling area").status, 0);
    ASSERT_EQ(run(base + "-o " + out.string() + " --light-sampling auto --stats " + stats.string()).status, 0);
    const auto j = nlohmann::json::parse(slurp(stats));
    EXPECT_EQ(j["auto_cheapest_lights"], c.cheapest) << c.lamp;
    EXPECT_EQ(j["light_sampling"], "auto") << c.lamp;
    if (c.cheapest) {
      EXPECT_EQ(diff_mse(), 0.0) << c.lamp;
    } else {
      EXPECT_GT(diff_mse(), 0.0) << c.lamp;
    }
    // With v_rest given there is no pilot, and no receivers to weigh at.
    ASSERT_EQ(run(base + "-o " + out.string() + " --light-sampling auto --auto-rest-variance 4 --stats " +
                  stats.string()).status, 0);
    EXPECT_FALSE(nlohmann::json::parse(slurp(stats)).contains("auto_cheapest_lights"));
  }
}

// `auto`'s choices follow from the scene, the seed and the pilot's counts,
// never from how long a run took (render/rest_cost.hpp): the same command
// gives the same image and the same settlement of its light (c_rest, kappa,
// V_l) for any thread count and on every run, here where kappa is measured
// (nee, and mis with R's weight; a large lamp low over the floor, Sobol
// samples; the image with one choice per pixel at the first surface).
TEST_F(Cli, AutoIsReproducible) {
  const std::string floor = R"({"type": "xz_rect", "x0": -5, "x1": 5, "z0": -5, "z1": 5, "k": 0, "material": "white"})";
  const std::string lamp = R"({"type": "xz_rect", "x0": -1.5, "x1": 1.5, "z0": -1.5, "z1": 1.5, "k": 0.3, "material": "light", "flip": true})";
  const fs::path s = write("lamp.json", scene_with(floor + ", " + lamp + R"(, {"type": "sphere", "center": [0.3, 0.1, -0.2], "radius": 0.1, "material": "white"})"));
  // With mis kappa_l is measured too (Sobol samples), and R weighed by it.
  for (const std::string integrator : {"nee", "mis"}) {
    std::vector<nlohmann::json> lights;
    for (const char* threads : {"1", "2", "2"}) {
      const fs::path out = dir / (integrator + std::to_string(lights.size()) + ".exr"), stats = dir / "s.json";
      ASSERT_EQ(run("render " + s.string() + " -o " + out.string() + " --width 64 --height 48 --spp 8 --seed 2 --max-depth 1 "
                    "--integrator " + integrator + " --light-sampling auto --quiet --threads " + threads + " --stats " +
                    stats.string()).status, 0);
      const auto j = nlohmann::json::parse(slurp(stats));
      ASSERT_EQ(j["auto_lights"].size(), 1u);
      lights.push_back(j["auto_lights"][0]);
      EXPECT_GT(lights.back()["gain_factor_seconds"].get<double>(), 0.0) << "kappa measured " << integrator;
      // Times: the parts that may differ.
      lights.back().erase("gain_factor_seconds");
      lights.back().erase("rest_pilot_seconds");
      EXPECT_LT(lights.back()["gain_factor"].get<double>(), 1.0) << "kappa measured " << integrator;
      // R's weight kappa_R / kappa_l where kappa_l < kappa_R = 1/sqrt(8), else 1.
      if (integrator == "mis") {
        EXPECT_NEAR(lights.back()["rest_weight"].get<double>(),
                    std::max(1.0, 1.0 / std::sqrt(8.0) / lights.back()["gain_factor"].get<double>()), 1e-9);
      }
      if (lights.size() > 1) {
        EXPECT_EQ(lights.back(), lights.front()) << integrator << " " << threads;
        const result r = run("diff " + out.string() + " " + (dir / (integrator + "0.exr")).string() + " --json");
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(nlohmann::json::parse(r.out)["mse"].get<double>(), 0.0) << integrator << " " << threads;
      }
    }
  }
}

// mcrt samples: the CSV of the contract, to a file or to stdout; samples on
// the light with their pdf, rows of pdf 0 where the light faces away; bad
// arguments refused with one line and exit 2, the output untouched.
TEST_F(Cli, SamplesWritesTheContractsCsv) {
  const fs::path scene = fs::path(MCRT_SCENES_DIR) / "cornell_rect.json", out = dir / "s.csv";
  const std::string base = "samples " + scene.string() + " --light 0 --from 278,1,279 --normal 0,1,0 ";
  for (const char* strategy : {"area", "solid-angle", "projected-solid-angle", "bilinear-solid-angle", "auto"}) {
    ASSERT_EQ(run(base + "--n 2000 --seed 4 --light-sampling " + strategy + " -o " + out.string()).status, 0);
    std::istringstream csv(slurp(out));
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "u1,u2,dx,dy,dz,px,py,pz,pdf");
    int rows = 0;
    double inv_pdf = 0.0;
    while (std::getline(csv, line)) {
      double v[9];
      char c;
      std::istringstream row(line);
      row >> v[0];
      for (int i = 1; i < 9; ++i) row >> c >> v[i];
      ASSERT_TRUE(row) << line;
      EXPECT_GE(v[0], 0.0);
      EXPECT_LT(v[0], 1.0);
      EXPECT_NEAR(v[2] * v[2] + v[3] * v[3] + v[4] * v[4], 1.0, 1e-5) << line;
      EXPECT_NEAR(v[6], 554.0, 1e-2) << "the point must lie on the light: " << line;
      EXPECT_TRUE(v[5] >= 213 - 1e-2 && v[5] <= 343 + 1e-2 && v[7] >= 227 - 1e-2 && v[7] <= 332 + 1e-2) << line;
      EXPECT_GT(v[8], 0.0);
      inv_pdf += 1.0 / v[8];
      ++rows;
    }
    EXPECT_EQ(rows, 2000);
    // E[1/pdf] is, for every strategy, the light's solid angle from
    // (278, 1, 279): 0.0441 sr (README's extremes table), to 3 %.
    EXPECT_NEAR(inv_pdf / rows, 0.04413, 0.03 * 0.04413) << strategy;
  }
  // To stdout, and from above the light (it faces down): rows of pdf 0.
  result r = run("samples " + scene.string() + " --light 0 --from 278,600,279 --normal 0,1,0 --n 3");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 4);
  EXPECT_NE(r.out.find(",0,0,0,0,0,0,0\n"), std::string::npos) << r.out;
  // The same seed gives the same samples.
  EXPECT_EQ(run(base + "--n 50 --seed 9").out, run(base + "--n 50 --seed 9").out);
  EXPECT_NE(run(base + "--n 50 --seed 9").out, run(base + "--n 50 --seed 10").out);

  expect_bad(base + "--n 0 -o " + out.string(), {"--n"}, out);
  expect_bad("samples " + scene.string() + " --light 1 --from 278,1,279 --normal 0,1,0 -o " + out.string(), {"--light", "1 light"}, out);
  expect_bad("samples " + scene.string() + " --light 0 --from 278,1 --normal 0,1,0 -o " + out.string(), {"--from"}, out);
  expect_bad("samples " + scene.string() + " --light 0 --from 278,1,279 --normal 0,0,0 -o " + out.string(), {"--normal"}, out);
  expect_bad("samples " + scene.string() + " --light 0 --from 278,1,279 -o " + out.string(), {"--normal"}, out);
  expect_bad(base + "--light-sampling sideways -o " + out.string(), {"--light-sampling"}, out);
  expect_bad("samples " + (dir / "missing.json").string() + " --light 0 --from 1,1,1 --normal 0,1,0 -o " + out.string(),
             {"missing.json"}, out);
  expect_bad(base + "-o " + (dir / "no_such_dir" / "s.csv").string(), {"no_such_dir"}, out);
}

TEST_F(Cli, EveryShippedSceneRenders) {
  for (const auto& e : fs::directory_iterator(MCRT_SCENES_DIR)) {
    if (e.path().extension() != ".json") continue;
    // Each integrator with another sample generator.
    for (const char* strategy : {"area", "solid-angle", "projected-solid-angle", "bilinear-solid-angle", "auto"})
      for (const auto& [integrator, sampler] : {std::pair{"mixture", "independent"}, {"nee", "stratified"}, {"mis", "sobol"}}) {
      const fs::path out = dir / (e.path().stem().string() + ".exr"), stats = dir / "s.json";
      const result r = run("render " + e.path().string() + " -o " + out.string() + " --width 24 --height 24 --spp 2 --light-sampling " +
                           strategy + " --integrator " + integrator + " --sampler " + sampler + " --stats " + stats.string() + " --quiet");
      EXPECT_EQ(r.status, 0) << e.path() << " " << strategy << " " << integrator << ": " << r.err;
      if (r.status == 0) {
        const auto j = nlohmann::json::parse(slurp(stats));
        EXPECT_EQ(j["nonfinite_samples"], 0) << e.path();
      }
    }
  }
}

// --ellipse-map polar (an extension of the contract): the disk scenes render
// with the polar map, and --stats says so; without ellipses it changes nothing.
TEST_F(Cli, EllipseMapPolarRendersTheDiskScenes) {
  for (const char* name : {"cornell_disk", "cornell_disk_large"}) {
    const fs::path scene = fs::path(MCRT_SCENES_DIR) / (std::string(name) + ".json");
    const fs::path out = dir / "polar.exr", stats = dir / "s.json";
    const result r = run("render " + scene.string() + " -o " + out.string() +
                         " --width 24 --height 24 --spp 2 --light-sampling solid-angle --ellipse-map polar --stats " +
                         stats.string() + " --quiet");
    ASSERT_EQ(r.status, 0) << name << ": " << r.err;
    const auto j = nlohmann::json::parse(slurp(stats));
    EXPECT_EQ(j["ellipse_map"], "polar");
    EXPECT_EQ(j["light_sampling"], "solid-angle");
    EXPECT_EQ(j["nonfinite_samples"], 0) << name;
  }
}
