#include "pbrt/builder.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "pbrt/materials.hpp"
#include "pbrt/params.hpp"
#include "pbrt/ply.hpp"
#include "pbrt/values.hpp"
#include "pbrt/spectrum.hpp"

namespace mcrt::pbrt {
namespace {

namespace fs = std::filesystem;

// The command line's limits (docs/cli.md), for what a file asks for.
constexpr int max_samples_per_pixel = 1 << 20;
constexpr int max_path_depth = 100000;


// The current material when it is "interface" (interface_material,
// materials.hpp): no surface. Shapes made under it are read and checked,
// and not added (rays pass them, as pbrt-v4's volpath lets every ray
// through them; its path stops light samples' shadow rays there); an area
// light on them is refused.

// What pbrt-v4's graphics state holds that mcrt uses.
struct graphics_state {
  transform ctm;
  bool reverse_orientation = false;
  // The current material: an index in the scene's materials.
  std::uint32_t material = 0;
  // The current area light, if any.
  struct area_light {
    color L{0.0f};
    bool twosided = false;
    file_loc loc;
  };
  std::optional<area_light> light;
  std::map<std::string, std::vector<param>> attribute_defaults;  // "shape", "light", "material", ...
};

class builder {
 public:
  builder(const std::string& dir, const build_options& opt) : dir_(dir), opt_(opt) {
    // pbrt-v4's default material: diffuse, reflectance 0.5.
    out_.world.materials.push_back(lambertian{color(0.5f)});
    state_.material = 0;
  }

  built_scene run(const std::vector<directive>& ds) {
    for (const directive& d : ds) step(d);
    if (!saw_world_) refuse(ds.empty() ? file_loc{} : ds.back().loc, "the file has no WorldBegin");
    if (!stack_.empty()) refuse(ds.back().loc, "AttributeBegin without AttributeEnd");
    if (out_.world.object_count() == 0) refuse(ds.back().loc, "the scene has no shapes");
    // The camera at the film's resolution, which must fit single precision.
    try {
      (void)perspective_camera(out_.camera_from_world, out_.perspective, out_.film.width, out_.film.height);
    } catch (const std::domain_error& e) {
      refuse(camera_loc_.file ? camera_loc_ : ds.front().loc, std::string("Camera: ") + e.what());
    }
    out_.world.build_accelerator();
    out_.world.build_light_tree();
    return std::move(out_);
  }

 private:
  std::string dir_;
  const build_options& opt_;
  built_scene out_;
  graphics_state state_;
  std::vector<std::pair<graphics_state, bool>> stack_;  // saved states; true: only the transform (TransformBegin)
  std::map<std::string, transform> coordinate_systems_;
  std::map<std::string, std::uint32_t> named_materials_;
  values values_;  // spectra, and the file's textures by name
  bool saw_world_ = false, saw_camera_ = false;
  file_loc camera_loc_;  // the Camera directive's place

  std::string resolve(const std::string& name) const {
    const fs::path p(name);
    return p.is_absolute() || dir_.empty() ? name : (fs::path(dir_) / p).string();
  }

  void step(const directive& d) {
    const std::string& n = d.name;
    if (n == "Identity") {
      state_.ctm = transform{};
    } else if (n == "Translate") {
      state_.ctm = state_.ctm * transform::translate({d.numbers[0], d.numbers[1], d.numbers[2]});
    } else if (n == "Scale") {
      state_.ctm = state_.ctm * transform::scale({d.numbers[0], d.numbers[1], d.numbers[2]});
    } else if (n == "Rotate") {
      const auto r = transform::rotate(d.numbers[0], {d.numbers[1], d.numbers[2], d.numbers[3]});
      if (!r) refuse(d.loc, "Rotate: the axis is zero");
      state_.ctm = state_.ctm * *r;
    } else if (n == "LookAt") {
      const auto l = transform::look_at({d.numbers[0], d.numbers[1], d.numbers[2]}, {d.numbers[3], d.numbers[4], d.numbers[5]},
                                        {d.numbers[6], d.numbers[7], d.numbers[8]});
      if (!l) refuse(d.loc, "LookAt: the eye is the point looked at, or up is parallel to the view direction");
      state_.ctm = state_.ctm * *l;
    } else if (n == "Transform" || n == "ConcatTransform") {
      std::array<double, 16> m;
      std::copy(d.numbers.begin(), d.numbers.end(), m.begin());
      const auto t = transform::from_pbrt_matrix(m);
      if (!t) refuse(d.loc, n + ": the matrix is singular");
      state_.ctm = n == "Transform" ? *t : state_.ctm * *t;
    } else if (n == "CoordinateSystem") {
      coordinate_systems_[d.strings[0]] = state_.ctm;
    } else if (n == "CoordSysTransform") {
      const auto it = coordinate_systems_.find(d.strings[0]);
      if (it == coordinate_systems_.end()) refuse(d.loc, "CoordSysTransform: no coordinate system named " + quoted(d.strings[0]));
      state_.ctm = it->second;
    } else if (n == "ReverseOrientation") {
      state_.reverse_orientation = !state_.reverse_orientation;
    } else if (n == "AttributeBegin" || n == "TransformBegin") {
      stack_.emplace_back(state_, n == "TransformBegin");
    } else if (n == "AttributeEnd" || n == "TransformEnd") {
      if (stack_.empty()) refuse(d.loc, n + " without a matching begin");
      auto [saved, only_transform] = std::move(stack_.back());
      stack_.pop_back();
      if (only_transform)
        state_.ctm = saved.ctm;
      else
        state_ = std::move(saved);
    } else if (n == "Attribute") {
      const std::string& kind = d.strings[0];
      if (kind != "shape" && kind != "light" && kind != "material" && kind != "medium" && kind != "texture")
        refuse(d.loc, "Attribute: unknown kind " + quoted(kind) + " (expected shape, light, material, medium or texture)");
      auto& defaults = state_.attribute_defaults[kind];
      for (const param& p : d.params) {
        std::erase_if(defaults, [&](const param& q) { return q.name == p.name; });
        defaults.push_back(p);
      }
    } else if (n == "WorldBegin") {
      if (saw_world_) refuse(d.loc, "WorldBegin: a second WorldBegin");
      saw_world_ = true;
      if (!saw_camera_) camera_default();
      state_.ctm = transform{};
      coordinate_systems_["world"] = transform{};
    } else if (n == "WorldEnd") {
      // pbrt-v3's end of the scene: nothing to do.
    } else if (n == "Camera") {
      camera(d);
    } else if (n == "Film") {
      film(d);
    } else if (n == "PixelFilter") {
      pixel_filter_directive(d);
    } else if (n == "Sampler") {
      sampler(d);
    } else if (n == "Integrator") {
      integrator(d);
    } else if (n == "Accelerator") {
      params p(d);
      for (const param& q : d.params) p.accept_any(q.name);  // the acceleration structure does not change the image
    } else if (n == "ColorSpace") {
      if (d.strings[0] != "srgb") refuse(d.loc, "ColorSpace " + quoted(d.strings[0]) + ": not supported (supported: srgb)");
    } else if (n == "Option") {
      option(d);
    } else if (n == "Material") {
      need_world(d);
      state_.material = material(d, d.type);
    } else if (n == "MakeNamedMaterial") {
      need_world(d);
      params p(d);
      const std::optional<std::string> type = p.string("type");
      if (!type) p.fail("has no \"string type\"");
      named_materials_[d.strings[0]] = material(d, *type);
    } else if (n == "NamedMaterial") {
      need_world(d);
      const auto it = named_materials_.find(d.strings[0]);
      if (it == named_materials_.end()) refuse(d.loc, "NamedMaterial: no material named " + quoted(d.strings[0]));
      state_.material = it->second;
    } else if (n == "Texture") {
      need_world(d);
      texture_directive(d);
    } else if (n == "AreaLightSource") {
      need_world(d);
      area_light(d);
    } else if (n == "Shape") {
      need_world(d);
      shape(d);
    } else if (n == "MediumInterface") {
      for (const std::string& s : d.strings)
        if (!s.empty()) refuse(d.loc, "MediumInterface: participating media are not supported");
    } else {
      // LightSource, MakeNamedMedium, ObjectBegin/End/Instance, TransformTimes,
      // ActiveTransform: known to the parser, not supported here.
      refuse(d.loc, n + (d.type.empty() ? "" : " " + quoted(d.type)) + ": not supported");
    }
  }

  void need_world(const directive& d) const {
    if (!saw_world_) refuse(d.loc, d.name + ": before WorldBegin");
  }

  // ---- options: camera, film, filter, sampler, integrator -------------------

  void camera_default() {
    out_.camera_from_world = transform{};
    out_.perspective = {};
  }

  void camera(const directive& d) {
    if (saw_world_) refuse(d.loc, "Camera: after WorldBegin");
    saw_camera_ = true;
    if (d.type != "perspective") refuse(d.loc, "Camera " + quoted(d.type) + ": not supported (supported: perspective)");
    params p(d);
    if (const std::optional<std::string> why = camera_matrix_problem(state_.ctm)) refuse(d.loc, "Camera: " + *why);
    camera_loc_ = d.loc;
    out_.camera_from_world = state_.ctm;
    coordinate_systems_["camera"] = state_.ctm.inverse();
    perspective_params& pp = out_.perspective;
    pp.fov = p.real("fov", 90.0);
    if (!(pp.fov > 0.0 && pp.fov < 180.0)) p.fail(*p.find("fov"), "must be in (0, 180) degrees");
    if (const auto a = p.number("frameaspectratio")) {
      if (!(*a > 0.0)) p.fail(*p.find("frameaspectratio"), "must be > 0");
      pp.frame_aspect_ratio = *a;
    }
    if (const param* sw = p.find("screenwindow")) {
      p.expect_type(*sw, {"float"});
      if (sw->numbers.size() != 4) p.fail(*sw, "must have 4 values");
      if (!(sw->numbers[1] > sw->numbers[0] && sw->numbers[3] > sw->numbers[2])) p.fail(*sw, "must be xmin xmax ymin ymax with xmin < xmax, ymin < ymax");
      pp.screen_window = std::array<double, 4>{sw->numbers[0], sw->numbers[1], sw->numbers[2], sw->numbers[3]};
    }
    pp.lens_radius = p.real("lensradius", 0.0);
    if (!(pp.lens_radius >= 0.0 && std::isfinite(pp.lens_radius))) p.fail(*p.find("lensradius"), "must be >= 0");
    pp.focal_distance = p.real("focaldistance", 1e6);
    if (!(pp.focal_distance > 0.0 && std::isfinite(pp.focal_distance)))
      p.fail(*p.find("focaldistance"), "must be > 0");
    p.accept_default("shutteropen", 0.0);
    p.accept_default("shutterclose", 1.0);
    p.finish();
  }

  void film(const directive& d) {
    if (d.type != "rgb" && d.type != "gbuffer") refuse(d.loc, "Film " + quoted(d.type) + ": not supported (supported: rgb, gbuffer)");
    params p(d);
    out_.film.width = p.integer("xresolution", 1280);
    out_.film.height = p.integer("yresolution", 720);
    if (out_.film.width < 1 || out_.film.height < 1 || out_.film.width > 16384 || out_.film.height > 16384)
      p.fail("the resolution must be in [1, 16384] per side");
    if (const auto f = p.string("filename")) out_.film.filename = *f;
    p.accept_any("savefp16");  // the output's precision
    p.accept_any("diagonal");  // the sensor's size: no effect on a perspective image
    p.accept_default("iso", 100.0);
    p.accept_default("exposuretime", 1.0);
    p.accept_default("whitebalance", 0.0);
    p.accept_default_string("sensor", "cie1931");
    p.finish();
  }

  void pixel_filter_directive(const directive& d) {
    params p(d);
    filter_desc& f = out_.filter;
    f.kind = d.type;
    if (d.type == "box") {
      f.radius = vec2(0.5f);
    } else if (d.type == "gaussian") {
      f.radius = vec2(1.5f);
      f.sigma = static_cast<float>(p.real("sigma", 0.5));
      if (!(f.sigma > 0.0f)) p.fail("sigma must be > 0");
    } else if (d.type == "triangle") {
      f.radius = vec2(2.0f);
    } else {
      refuse(d.loc, "PixelFilter " + quoted(d.type) + ": not supported (supported: box, gaussian, triangle)");
    }
    f.radius.x = static_cast<float>(p.real("xradius", f.radius.x));
    f.radius.y = static_cast<float>(p.real("yradius", f.radius.y));
    if (!(f.radius.x > 0.0f && f.radius.y > 0.0f)) p.fail("the radii must be > 0");
    p.finish();
  }

  void sampler(const directive& d) {
    params p(d);
    const std::string& t = d.type;
    if (t == "independent") {
      out_.sampler = "independent";
      out_.spp = p.integer("pixelsamples", 4);
    } else if (t == "stratified") {
      out_.sampler = "stratified";
      const int x = p.integer("xsamples", 4), y = p.integer("ysamples", 4);
      if (x < 1 || y < 1) p.fail("xsamples and ysamples must be >= 1");
      if (static_cast<long long>(x) * y > max_samples_per_pixel)
        p.fail("xsamples x ysamples must be at most " + std::to_string(max_samples_per_pixel));
      out_.spp = x * y;
      p.accept_any("jitter");  // jittered or not: the expected image is the same
    } else if (t == "sobol" || t == "zsobol" || t == "paddedsobol" || t == "halton" || t == "pmj02bn") {
      out_.sampler = "sobol";
      out_.spp = p.integer("pixelsamples", 16);
      p.accept_any("randomization");
    } else {
      refuse(d.loc, "Sampler " + quoted(t) +
                        ": not supported (supported: independent, stratified, sobol, zsobol, paddedsobol, halton, pmj02bn)");
    }
    p.accept_any("seed");
    if (out_.spp < 1 || out_.spp > max_samples_per_pixel)
      p.fail("the sample count must be in [1, " + std::to_string(max_samples_per_pixel) + "]");
    p.finish();
  }

  // pbrt-v4's integrators. Those that converge to path's image on every
  // scene mcrt accepts (bdpt, mlt, sppm, simplepath, simplevolpath, and
  // path and volpath themselves) are rendered by mcrt's own integrator at
  // the Sampler's pixelsamples, and --stats names the one the file asked
  // for (integrator_requested); each one's parameters are those its
  // pbrt-v4 Create reads, checked and otherwise not used (mlt's
  // mutationsperpixel and sppm's photons set no sample count). Those that
  // compute another image or another quantity are refused.
  void integrator(const directive& d) {
    static const std::set<std::string> same_image = {"path", "volpath", "simplepath", "simplevolpath",
                                                     "bdpt", "mlt", "sppm"};
    if (d.type == "randomwalk" || d.type == "lightpath")
      refuse(d.loc, "Integrator " + quoted(d.type) +
                        ": not supported (its image differs from path's on mirrors, glass and delta lights; "
                        "supported: path, volpath, simplepath, simplevolpath, bdpt, mlt, sppm)");
    if (d.type == "ambientocclusion" || d.type == "function")
      refuse(d.loc, "Integrator " + quoted(d.type) +
                        ": not supported (it computes another quantity than radiance; supported: path, volpath, "
                        "simplepath, simplevolpath, bdpt, mlt, sppm)");
    if (!same_image.contains(d.type))
      refuse(d.loc, "Integrator " + quoted(d.type) +
                        ": not supported (supported: path, volpath, simplepath, simplevolpath, bdpt, mlt, sppm)");
    out_.integrator_requested = d.type;
    params p(d);
    out_.max_depth = p.integer("maxdepth", 5);
    if (out_.max_depth < 0 || out_.max_depth > max_path_depth)
      p.fail("maxdepth must be in [0, " + std::to_string(max_path_depth) + "]");
    if (d.type != "simplepath" && d.type != "simplevolpath" && d.type != "sppm")
      if (p.boolean("regularize", false)) p.fail(*p.find("regularize"), "true is not supported");
    if (d.type == "path" || d.type == "volpath") {
      if (const auto ls = p.string("lightsampler")) {
        if (*ls == "uniform" || *ls == "power" || *ls == "bvh")
          out_.light_select = *ls;
        else
          p.fail(*p.find("lightsampler"), "must be uniform, power or bvh");
      }
    } else if (d.type == "simplepath") {
      // Without light samples (BSDF samples meeting the emitters) the image
      // is path's on every scene mcrt accepts (it has no delta lights yet);
      // without BSDF samples pbrt-v4 samples directions uniformly, which
      // never finds a mirror's or a pane's direction: another image.
      p.boolean("samplelights", true);
      if (!p.boolean("samplebsdf", true))
        p.fail(*p.find("samplebsdf"), "false is not supported (uniform directions miss every specular surface)");
    } else if (d.type == "bdpt") {
      for (const char* v : {"visualizestrategies", "visualizeweights"})
        if (p.boolean(v, false))
          p.fail(*p.find(v), "true is not supported (it renders an image per strategy, not the scene)");
    } else if (d.type == "mlt") {
      // pbrt-v4's MLTIntegrator::Create: its sample counts and mutation
      // sizes; mcrt takes the Sampler's pixelsamples instead.
      for (const char* n : {"bootstrapsamples", "chains", "mutationsperpixel"})
        if (const param* q = p.find(n); q && p.integer(n, 1) < 1) p.fail(*q, "must be >= 1");
      const double large = p.real("largestepprobability", 0.3), sigma = p.real("sigma", 0.01);
      if (!(large >= 0.0 && large <= 1.0)) p.fail(*p.find("largestepprobability"), "must be in [0, 1]");
      if (!(sigma > 0.0) || !std::isfinite(sigma)) p.fail(*p.find("sigma"), "must be > 0");
    } else if (d.type == "sppm") {
      // pbrt-v4's SPPMIntegrator::Create: photons per iteration (-1: one
      // per pixel), the initial search radius and a seed.
      p.integer("photonsperiteration", -1);
      const double radius = p.real("radius", 1.0);
      if (!(radius > 0.0) || !std::isfinite(radius)) p.fail(*p.find("radius"), "must be > 0");
      p.accept_any("seed");
    }
    p.finish();
  }

  void option(const directive& d) {
    for (const param& q : d.params)
      if (q.name != "rendercoordsys" && q.name != "seed")
        refuse(q.loc, "Option " + quoted(q.type + " " + q.name) + ": not supported (supported: rendercoordsys, seed)");
  }

  // ---- spectra, textures, materials ----------------------------------------

  void texture_directive(const directive& d) {
    const std::string& name = d.strings[0];
    const std::string& type = d.strings[1];
    const std::string& cls = d.strings[2];
    if (type != "spectrum" && type != "float" && type != "color")
      refuse(d.loc, "Texture " + quoted(name) + ": type " + quoted(type) + " (expected spectrum or float)");
    const bool is_float = type == "float";
    params p(d, attribute_defaults("texture"));
    auto t = std::make_shared<texture>();
    const auto mapping = [&] {
      const std::optional<std::string> m = p.string("mapping");
      if (m && *m != "uv") p.fail(*p.find("mapping"), "must be uv (the only mapping supported)");
      t->mapping = {float(p.real("uscale", 1.0)), float(p.real("vscale", 1.0)), float(p.real("udelta", 0.0)),
                    float(p.real("vdelta", 0.0))};
    };
    const auto value = [&](const std::string& pname, float def) {
      return is_float ? values_.float_texture(p, pname, def) : values_.spectrum_texture(p, pname, color(def));
    };
    if (cls == "constant") {
      t = std::make_shared<texture>(*value("value", 1.0f));
    } else if (cls == "scale") {
      t->k = texture::kind::scale;
      t->a = value("tex", 1.0f);
      t->b = values_.float_texture(p, "scale", 1.0f);
    } else if (cls == "checkerboard") {
      t->k = texture::kind::checkerboard;
      mapping();
      if (p.integer("dimension", 2) != 2) p.fail("only dimension 2 is supported");
      t->a = value("tex1", 1.0f);
      t->b = value("tex2", 0.0f);
    } else if (cls == "imagemap") {
      t->k = texture::kind::image;
      mapping();
      const std::optional<std::string> file = p.string("filename");
      if (!file) p.fail("has no \"string filename\"");
      const std::string encoding = p.string("encoding").value_or("sRGB");
      if (!(encoding == "sRGB" || encoding == "linear" || encoding.rfind("gamma ", 0) == 0))
        p.fail(*p.find("encoding"), "must be sRGB, linear or \"gamma G\"");
      if (encoding.rfind("gamma ", 0) == 0) {
        const std::optional<double> g = parse_number(encoding.substr(6));
        if (!g || !(*g > 0.0) || !std::isfinite(static_cast<float>(*g)))
          p.fail(*p.find("encoding"), "must be \"gamma G\" with a finite G > 0");
      }
      const std::string wrap = p.string("wrap").value_or("repeat");
      if (wrap == "repeat")
        t->wrap = texture_wrap::repeat;
      else if (wrap == "clamp")
        t->wrap = texture_wrap::clamp;
      else if (wrap == "black")
        t->wrap = texture_wrap::black;
      else
        p.fail(*p.find("wrap"), "must be repeat, clamp or black");
      // The mip-map filters are evaluated bilinearly at the finest level.
      const std::optional<std::string> filter = p.string("filter");
      if (filter && *filter != "bilinear" && *filter != "trilinear" && *filter != "ewa" && *filter != "point")
        p.fail(*p.find("filter"), "must be point, bilinear, trilinear or ewa");
      p.accept_any("maxanisotropy");
      t->value = color(float(p.real("scale", 1.0)));
      t->invert = p.boolean("invert", false);
      if (!opt_.decode_image) p.fail("images cannot be decoded here");
      const std::string path = resolve(*file);
      try {
        auto img = std::make_shared<texture_image>(opt_.decode_image(path, encoding, opt_.max_input_bytes));
        if (is_float)
          for (color& c : img->texels) c = color((c.r + c.g + c.b) / 3.0f);
        t->img = std::move(img);
      } catch (const parse_error&) {
        throw;
      } catch (const std::exception& e) {
        refuse(p.loc(), "Texture " + quoted(name) + ": " + quote_prefix(path, 200) + ": " + e.what());
      }
    } else {
      refuse(d.loc, "Texture " + quoted(name) + " class " + quoted(cls) +
                        ": not supported (supported: imagemap, constant, scale, checkerboard)");
    }
    p.finish();
    (is_float ? values_.float_textures : values_.spectrum_textures)[name] = {t, is_float};
  }

  const std::vector<param>* attribute_defaults(const std::string& kind) const {
    const auto it = state_.attribute_defaults.find(kind);
    return it == state_.attribute_defaults.end() ? nullptr : &it->second;
  }

  // Makes the material of a Material or MakeNamedMaterial directive and
  // returns its index.
  std::uint32_t material(const directive& d, const std::string& type) {
    params p(d, attribute_defaults("material"));
    if (d.name == "MakeNamedMaterial") p.string("type");
    if (p.find("displacement")) p.fail(*p.find("displacement"), "is not supported");
    if (p.find("normalmap")) p.fail(*p.find("normalmap"), "is not supported");
    const std::optional<mcrt::material> m = make_material(d.name, type, p, values_, named_materials_);
    p.finish();
    if (!m) return interface_material;
    out_.world.materials.push_back(*m);
    return static_cast<std::uint32_t>(out_.world.materials.size() - 1);
  }

  void area_light(const directive& d) {
    if (d.type != "diffuse") refuse(d.loc, "AreaLightSource " + quoted(d.type) + ": not supported (supported: diffuse)");
    params p(d, attribute_defaults("light"));
    graphics_state::area_light l;
    l.loc = d.loc;
    // pbrt-v4's DiffuseAreaLight::Create: L (default the illuminant, white
    // of luminance 1 here), scale divided by L's luminance (an rgb L is
    // taken as it is: mcrt renders in RGB, pbrt-v4 divides by its
    // illuminant's luminance only).
    color L = values_.spectrum(p, "L", spectrum_use::illuminant).value_or(color(1.0f));
    const float scale = static_cast<float>(p.real("scale", 1.0));
    // A negative scale would make a light of negative power, which no
    // light selection can choose by (pbrt-v4 does not check it either).
    if (!(scale >= 0.0f)) p.fail(*p.find("scale"), "must be >= 0");
    L *= scale;
    if (!all_finite(L))
      p.fail("the radiance L times scale overflows single precision (beyond 3.4e38)");
    l.twosided = p.boolean("twosided", false);
    if (p.find("filename")) p.fail(*p.find("filename"), "(an image on the light) is not supported");
    if (p.find("power")) p.fail(*p.find("power"), "is not supported");
    p.finish();
    l.L = L;
    state_.light = l;
  }

  // ---- shapes ----------------------------------------------------------------

  // The material a shape gets: its own, or for an emitter a diffuse_light
  // that reflects with it.
  std::uint32_t shape_material(bool& emits) {
    emits = state_.light && state_.light->L != color(0.0f);
    if (state_.material == interface_material) {
      // pbrt-v4 drops the light with a warning (scene.cpp): mcrt ignores
      // nothing silently.
      if (state_.light)
        refuse(state_.light->loc, "AreaLightSource on a shape with the interface material (no surface; pbrt-v4 drops "
                                  "the light with a warning)");
      emits = false;
    }
    if (!emits) return state_.material;
    diffuse_light dl;
    dl.emit = state_.light->L;
    dl.twosided = state_.light->twosided;
    // A black diffuse material reflects nothing: the light is a pure emitter.
    const mcrt::material& m = out_.world.materials[state_.material];
    const auto* lam = std::get_if<lambertian>(&m);
    dl.surface = lam && lam->albedo == color(0.0f) ? diffuse_light::no_surface : state_.material;
    out_.world.materials.push_back(dl);
    return static_cast<std::uint32_t>(out_.world.materials.size() - 1);
  }

  // --light-sampling, else the shape's default; `auto` in the noise
  // pilot's scene is the default (the shape's cheapest strategy).
  light_sampling strategy_for(light_sampling def) const {
    if (!opt_.strategy) return def;
    if (*opt_.strategy == light_sampling::automatic && opt_.auto_pilot) return def;
    return *opt_.strategy;
  }
  bool automatic() const { return opt_.strategy == light_sampling::automatic; }

  // `auto`'s params for a light of radiance L (the mean of its channels,
  // as for JSON scenes), and an `auto` light built by make() with them, its
  // set-up timed.
  template <class Make>
  light auto_light(const color& L, Make make) {
    auto_params p = opt_.auto_rule;
    p.radiance = (L.r + L.g + L.b) / 3.0f;
    const auto start = std::chrono::steady_clock::now();
    light l = make(p);
    out_.auto_setup_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return l;
  }

  // Registers an emitter's light(s): one, or for a two-sided light its
  // front and its back (each a one-sided light sampled from its own side,
  // so every strategy serves both and the power counts both).
  template <class Front, class Back>
  void add_emitter(Front&& front, Back&& back, bool twosided, std::uint32_t mat) {
    std::vector<std::uint32_t> entries;
    entries.push_back(static_cast<std::uint32_t>(out_.world.emitters.size()));
    front(mat);
    if (twosided) {
      entries.push_back(static_cast<std::uint32_t>(out_.world.emitters.size()));
      back(mat);
    }
    out_.file_lights.push_back(std::move(entries));
  }

  void add_light_only(const light& l, std::uint32_t mat) {
    if (automatic()) ++out_.auto_lights;
    const auto k = static_cast<std::uint32_t>(out_.world.lights.size());
    out_.world.lights.push_back(l);
    const auto& e = std::get<diffuse_light>(out_.world.materials[mat]);
    out_.world.emitters.push_back({k, pi * surface_area(l) * luminance(e.emit)});
  }

  void shape(const directive& d) {
    params p(d, attribute_defaults("shape"));
    p.accept_any("alpha");
    if (const param* a = p.find("alpha"))
      if (!(a->type == "float" && a->numbers.size() == 1 && a->numbers[0] == 1.0)) p.fail(*a, "(cut-outs) is not supported");
    p.accept_any("emissionfilename");
    if (p.find("emissionfilename")) p.fail(*p.find("emissionfilename"), "is not supported");
    const std::string& t = d.type;
    if (t == "trianglemesh") {
      triangle_mesh m;
      read_points_and_normals(p, m);
      m.indices = read_indices(p, m.p.size(), 3, "triangle");
      if (!read_uv(p, "uv", {"point2", "float"}, m)) read_uv(p, "st", {"point2", "float"}, m);
      if (p.find("S")) p.fail(*p.find("S"), "(shading tangents) is not supported");
      p.accept_any("faceIndices");  // face numbers matter only to Ptex textures
      p.finish();
      add_mesh(std::move(m), p);
    } else if (t == "plymesh") {
      const std::optional<std::string> file = p.string("filename");
      if (!file) p.fail("has no \"string filename\"");
      if (p.find("displacement")) p.fail(*p.find("displacement"), "is not supported");
      p.accept_default("edgelength", 1.0);
      p.finish();
      triangle_mesh m;
      try {
        m = read_ply(resolve(*file), opt_.max_input_bytes);
      } catch (const parse_error& e) {
        // Both places: the directive, and the PLY file's own.
        p.fail(e.what());
      }
      add_mesh(std::move(m), p);
    } else if (t == "bilinearmesh") {
      bilinear_mesh(p);
    } else if (t == "sphere") {
      sphere_shape(p);
    } else if (t == "disk") {
      disk_shape(p);
    } else {
      refuse(d.loc, "Shape " + quoted(t) + ": not supported (supported: trianglemesh, plymesh, bilinearmesh, sphere, disk)");
    }
  }

  // A mesh in object space: moved to the world by the CTM, checked, added
  // with the current material, and its triangles as lights where it emits.
  void add_mesh(triangle_mesh m, params& p) {
    const transform& x = state_.ctm;
    for (vec3& v : m.p) {
      v = vec3(x.point(glm::dvec3(v)));
      if (!all_finite(v)) p.fail("has a point that is not finite (after the transformation)");
    }
    // Shading normals move as normals, and ReverseOrientation turns them
    // (pbrt-v4's TriangleMesh and BilinearPatchMesh negate N under it; a
    // mirroring transform does not).
    for (vec3& n : m.n) {
      const glm::dvec3 w = x.normal(glm::dvec3(n));
      const double len = glm::length(w);
      n = len > 0.0 ? vec3(w / len) : vec3(0.0f);
      if (state_.reverse_orientation) n = -n;
    }
    // pbrt-v4's triangles: the geometric normal is the world-space cross
    // product, reversed by ReverseOrientation and by a transform that swaps
    // handedness (Triangle::InteractionFromIntersection), or turned to the
    // shading normals where the mesh has them.
    m.reverse_orientation = state_.reverse_orientation != x.swaps_handedness();
    auto mesh = std::make_shared<const triangle_mesh>(std::move(m));
    bool emits = false;
    const std::uint32_t mat = shape_material(emits);
    if (mat == interface_material) return;  // no surface: rays pass
    const light_sampling st = emits ? strategy_for(light_sampling::area) : light_sampling::area;
    for (const triangle& tri : triangles_of(mesh)) {
      if (tri.area() == 0.0f) continue;  // a degenerate triangle is never hit
      out_.world.add(tri, mat);
      if (emits)
        add_emitter([&](std::uint32_t mm) { add_light_only(triangle_light(tri, st, false), mm); },
                    [&](std::uint32_t mm) { add_light_only(triangle_light(tri, st, true), mm); },
                    state_.light->twosided, mat);
    }
  }

  // A triangle light's strategy (back: its back side's, for a two-sided light).
  light triangle_light(const triangle& t, light_sampling st, bool back) {
    switch (st) {
      case light_sampling::automatic:
        return auto_light(state_.light->L, [&](const auto_params& ap) { return triangle_auto_sampler(t, ap, back); });
      case light_sampling::solid_angle: return triangle_solid_angle_sampler{t, back};
      case light_sampling::projected_solid_angle: return triangle_projected_solid_angle_sampler{t, back};
      case light_sampling::bilinear_solid_angle: return triangle_bilinear_solid_angle_sampler{t, back};
      case light_sampling::pbrt: return triangle_pbrt_sampler{t, back};
      default: return triangle_area_sampler{t, back};
    }
  }

  // A mesh directive's "P" (required) and "N" (optional, one per point).
  static void read_points_and_normals(params& p, triangle_mesh& m) {
    const std::vector<double> P = p.numbers("P", {"point3", "point"}, 3);
    if (P.empty()) p.fail("has no \"point3 P\"");
    for (std::size_t i = 0; i < P.size(); i += 3) m.p.push_back(vec3(float(P[i]), float(P[i + 1]), float(P[i + 2])));
    const std::vector<double> N = p.numbers("N", {"normal", "normal3"}, 3);
    if (!N.empty()) {
      if (N.size() != P.size()) p.fail(*p.find("N"), "must have one normal per point");
      for (std::size_t i = 0; i < N.size(); i += 3) m.n.push_back(vec3(float(N[i]), float(N[i + 1]), float(N[i + 2])));
    }
  }

  // A mesh directive's "indices", `group` per face, each checked against
  // the number of points; absent, 0 .. group - 1 for a single face of
  // `group` points (pbrt-v4's rule).
  static std::vector<std::uint32_t> read_indices(params& p, std::size_t points, std::size_t group, const char* face) {
    std::vector<double> idx = p.numbers("indices", {"integer"}, group);
    if (idx.empty()) {
      if (points != group)
        p.fail("has no \"integer indices\" (allowed only for a single " + std::string(face) + " of " +
               std::to_string(group) + " points)");
      for (std::size_t k = 0; k < group; ++k) idx.push_back(double(k));
    }
    std::vector<std::uint32_t> out;
    out.reserve(idx.size());
    for (const double v : idx) {
      if (v < 0 || v >= double(points) || v != std::floor(v))
        p.fail(*p.find("indices"), "has an index out of range: " + std::to_string(static_cast<long long>(v)) + " (" +
                                       std::to_string(points) + " points)");
      out.push_back(static_cast<std::uint32_t>(v));
    }
    return out;
  }

  // The texture coordinates `name`, one point per point; false where absent.
  static bool read_uv(params& p, const char* name, std::initializer_list<const char*> types, triangle_mesh& m) {
    const std::vector<double> uv = p.numbers(name, types, 2);
    if (uv.empty()) return false;
    if (uv.size() / 2 != m.p.size()) p.fail("uv must have one point per point");
    for (std::size_t i = 0; i < uv.size(); i += 2) m.uv.push_back(vec2(float(uv[i]), float(uv[i + 1])));
    return true;
  }

  void bilinear_mesh(params& p) {
    triangle_mesh m;
    read_points_and_normals(p, m);
    const std::vector<std::uint32_t> idx = read_indices(p, m.p.size(), 4, "patch");
    const bool has_uv = read_uv(p, "uv", {"point2"}, m);
    if (!has_uv) {
      // pbrt-v4's patch parameterisation: p00 (0,0), p10 (1,0), p01 (0,1),
      // p11 (1,1); on a planar parallelogram the triangles interpolate it
      // exactly. Points shared by patches with different corners get the
      // first patch's; mcrt's triangles then differ from pbrt-v4's
      // bilinear (u, v) (textures only).
      m.uv.assign(m.p.size(), vec2(0.0f));
    }
    p.accept_any("faceIndices");
    p.finish();
    for (std::size_t i = 0; i < idx.size(); i += 4) {
      const std::array<std::uint32_t, 4> v{idx[i], idx[i + 1], idx[i + 2], idx[i + 3]};
      // Patch p00 p10 p01 p11 -> the quad p00 p10 p11 p01 -> triangles
      // (p00, p10, p11) and (p00, p11, p01); their normal is the patch's
      // cross(p10 - p00, p01 - p00) where the patch is planar and convex.
      const vec3 a = m.p[v[0]], b = m.p[v[1]], c = m.p[v[3]], e = m.p[v[2]];
      const vec3 n = glm::cross(b - a, e - a);
      const float scale = glm::length(b - a) + glm::length(c - a) + glm::length(e - a);
      if (std::abs(glm::dot(glm::normalize(n), c - a)) > 1e-5f * scale)
        p.fail("patch " + std::to_string(i / 4) + " is not planar (bilinear patches are supported when planar)");
      if (glm::dot(glm::cross(b - a, c - a), n) <= 0.0f || glm::dot(glm::cross(c - a, e - a), n) <= 0.0f)
        p.fail("patch " + std::to_string(i / 4) + " is not convex");
      if (!has_uv) {
        m.uv[v[0]] = {0, 0};
        m.uv[v[1]] = {1, 0};
        m.uv[v[2]] = {0, 1};
        m.uv[v[3]] = {1, 1};
      }
      m.indices.insert(m.indices.end(), {v[0], v[1], v[3], v[0], v[3], v[2]});
    }
    add_mesh(std::move(m), p);
  }

  // The CTM as a similarity (rotation, uniform scale, translation, perhaps
  // a mirror): its scale, or nullopt.
  std::optional<double> similarity_scale() const {
    const glm::dmat3 a(state_.ctm.m);
    const double s0 = glm::length(a[0]), s1 = glm::length(a[1]), s2 = glm::length(a[2]);
    const double s = (s0 + s1 + s2) / 3.0;
    const double tol = 1e-6 * s;
    if (std::abs(s0 - s) > tol || std::abs(s1 - s) > tol || std::abs(s2 - s) > tol) return std::nullopt;
    if (std::abs(glm::dot(a[0], a[1])) > tol * s || std::abs(glm::dot(a[1], a[2])) > tol * s ||
        std::abs(glm::dot(a[0], a[2])) > tol * s)
      return std::nullopt;
    return s;
  }

  void sphere_shape(params& p) {
    const double r = p.real("radius", 1.0);
    if (!(r > 0.0)) p.fail("radius must be > 0");
    p.accept_default("zmin", -r);
    p.accept_default("zmax", r);
    p.accept_default("phimax", 360.0);
    p.finish();
    const std::optional<double> s = similarity_scale();
    if (!s) p.fail("a sphere under a transformation that is not a similarity (an ellipsoid) is not supported");
    sphere sp;
    sp.center = vec3(state_.ctm.point({0, 0, 0}));
    sp.radius = static_cast<float>(r * *s);
    // pbrt-v4's intersection: the outward normal, flipped by
    // ReverseOrientation and by a transform that swaps handedness.
    sp.flip = state_.reverse_orientation != state_.ctm.swaps_handedness();
    bool emits = false;
    const std::uint32_t mat = shape_material(emits);
    if (mat == interface_material) return;  // no surface: rays pass
    if (!emits) {
      out_.world.add(sp, mat);
      return;
    }
    if (state_.light->twosided) p.fail("a two-sided sphere light is not supported");
    out_.world.add(sp, mat);
    const light_sampling st = strategy_for(light_sampling::solid_angle);
    add_emitter([&](std::uint32_t mm) { add_light_only(sphere_light(sp, st), mm); }, [](std::uint32_t) {}, false, mat);
  }

  light sphere_light(const sphere& s, light_sampling st) {
    switch (st) {
      case light_sampling::automatic:
        return auto_light(state_.light->L, [&](const auto_params& ap) { return sphere_auto_sampler(s, ap); });
      case light_sampling::area: return sphere_area_sampler{s};
      case light_sampling::projected_solid_angle:
      case light_sampling::bilinear_solid_angle: return sphere_projected_solid_angle_sampler{s};
      default: return sphere_cone_sampler{s};
    }
  }
  light ellipse_light(const ellipse& e, light_sampling st) {
    switch (st) {
      case light_sampling::automatic:
        return auto_light(state_.light->L, [&](const auto_params& ap) { return ellipse_auto_sampler(e, ap); });
      case light_sampling::solid_angle: return ellipse_solid_angle_sampler{e};
      case light_sampling::projected_solid_angle: return ellipse_projected_solid_angle_sampler{e};
      case light_sampling::bilinear_solid_angle: return ellipse_bilinear_solid_angle_sampler{e};
      default: return ellipse_area_sampler{e};
    }
  }

  void disk_shape(params& p) {
    const double r = p.real("radius", 1.0), h = p.real("height", 0.0);
    if (!(r > 0.0)) p.fail("radius must be > 0");
    p.accept_default("innerradius", 0.0);
    p.accept_default("phimax", 360.0);
    p.finish();
    const transform& x = state_.ctm;
    const glm::dvec3 c = x.point({0, 0, h}), a1 = x.vector({r, 0, 0}), a2 = x.vector({0, r, 0});
    if (std::abs(glm::dot(a1, a2)) > 1e-6 * glm::length(a1) * glm::length(a2))
      p.fail("a disk under a shear (its axes no longer orthogonal) is not supported");
    // pbrt-v4's intersection: the transformed +z normal, flipped by
    // ReverseOrientation and by a transform that swaps handedness.
    glm::dvec3 n = x.normal({0, 0, 1});
    if (state_.reverse_orientation != x.swaps_handedness()) n = -n;
    const bool flip = glm::dot(glm::cross(a1, a2), n) < 0.0;
    const ellipse e = ellipse::make(vec3(c), vec3(a1), vec3(a2), flip);
    bool emits = false;
    const std::uint32_t mat = shape_material(emits);
    if (mat == interface_material) return;  // no surface: rays pass
    out_.world.add(e, mat);
    if (!emits) return;
    const light_sampling st = strategy_for(light_sampling::area);
    add_emitter([&](std::uint32_t mm) { add_light_only(ellipse_light(e, st), mm); },
                [&](std::uint32_t mm) { add_light_only(ellipse_light(ellipse::make(vec3(c), vec3(a1), vec3(a2), !flip), st), mm); },
                state_.light->twosided, mat);
  }
};

}  // namespace

built_scene build_scene(const std::vector<directive>& directives, const std::string& scene_directory,
                        const build_options& options) {
  builder b(scene_directory, options);
  return b.run(directives);
}

built_scene load_pbrt_file(const std::string& path, const build_options& options) {
  parse_options po;
  po.max_input_bytes = options.max_input_bytes;
  const std::vector<directive> ds = parse_file(path, po);
  return build_scene(ds, fs::path(path).parent_path().string(), options);
}

}  // namespace mcrt::pbrt
