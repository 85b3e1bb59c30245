// mcrt's BVH (accel/bvh.hpp) against Embree 3 on one mesh of 1.29 million
// triangles: build time, closest-hit and shadow (any-hit) rays per second
// of single incoherent rays, one thread. Built only with Embree
// (bench/CMakeLists.txt, MCRT_BENCH_EMBREE=ON):
//   cmake -S . -B build-embree -DMCRT_BENCH_EMBREE=ON
//   cmake --build build-embree --target mcrt_bench_accel_embree
//   build-embree/mcrt_bench_accel_embree [rounds]
//
// The mesh (deterministic): a cube-mapped sphere of radius 1, 6 x 290 x 290
// quads (1,009,200 triangles), displaced radially by value-noise fBm
// (+-8 %), with 160 smaller displaced spheres inside it (6 x 12 x 12 quads,
// 1,728 triangles each; radii 0.04 to 0.12): a closed room with clutter,
// triangles of edge 0.004 to 0.01.
// Rays (fixed seeds, the same set for both): 2^20 closest-hit rays from
// uniform points of the mesh's bounding box in uniform directions
// (t in (0, inf)); 2^20 shadow segments between two uniform points of that
// box (t in (0, distance)).
//
// Measured, A/B interleaved in every round (the machine drifts):
//   build: mcrt's bvh from the triangles' bounds, with the vertices copied
//          in leaf order (what basic_scene::build_accelerator does), and the
//          scene's build_accelerator itself; Embree's rtcCommitScene at
//          RTC_BUILD_QUALITY_MEDIUM (its default) and HIGH (spatial splits),
//          on a device of one thread ("threads=1") and on its default
//          device (TBB, every core).
//   closest: mcrt's bvh::closest_leaf with the watertight test of a leaf's
//          triangles at once (geometry/triangle_leaf.hpp) on the vertices in
//          leaf order ("bare"), basic_scene::hit (the hit record of the
//          closest hit included: "scene"), against rtcIntersect1.
//   shadow: bvh::any_leaf (first hit ends the traversal) against
//          rtcOccluded1.
// Embree's scenes are built with its default flags (its fast, not watertight
// triangle test) and, for MEDIUM, also RTC_SCENE_FLAG_ROBUST.
// Cross-check: hit or miss, t and triangle of every closest-hit ray, blocked
// or not of every shadow ray, mcrt against Embree; the bench fails (exit 1)
// when more than 1e-4 of the rays disagree.
#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "mcrt/mcrt.hpp"

using namespace mcrt;

namespace {

using clock_type = std::chrono::steady_clock;
double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

// ---------------------------------------------------------------- the mesh

float lattice(int x, int y, int z) {
  std::uint32_t h = static_cast<std::uint32_t>(x) * 0x8da6b343u ^ static_cast<std::uint32_t>(y) * 0xd8163841u ^
                    static_cast<std::uint32_t>(z) * 0xcb1ab31fu;
  h ^= h >> 15;
  h *= 0x2c1b3c6du;
  h ^= h >> 12;
  h *= 0x297a2d39u;
  h ^= h >> 15;
  return static_cast<float>(h >> 8) * 0x1p-23f - 1.0f;  // [-1, 1)
}

float value_noise(const vec3& p) {
  const vec3 f = glm::floor(p);
  const vec3 t = p - f;
  const vec3 s = t * t * (3.0f - 2.0f * t);
  const int x = static_cast<int>(f.x), y = static_cast<int>(f.y), z = static_cast<int>(f.z);
  float v[2][2];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      v[i][j] = glm::mix(lattice(x, y + i, z + j), lattice(x + 1, y + i, z + j), s.x);
  return glm::mix(glm::mix(v[0][0], v[1][0], s.y), glm::mix(v[0][1], v[1][1], s.y), s.z);
}

float fbm(vec3 p) {
  float sum = 0.0f, amp = 0.5f;
  for (int o = 0; o < 5; ++o, p *= 2.03f, amp *= 0.5f) sum += amp * value_noise(p);
  return sum;  // about [-1, 1]
}

// A cube-mapped sphere (n x n quads on each face, equal-angle mapping) at
// `centre`, radius r (1 + amp fbm(freq dir + shift)).
void add_sphere(triangle_mesh& m, const vec3& centre, float r, int n, float amp, float freq, const vec3& shift) {
  for (int f = 0; f < 6; ++f) {
    const int a = f / 2;
    const float s = (f % 2) ? -1.0f : 1.0f;
    const auto base = static_cast<std::uint32_t>(m.p.size());
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        const float u = std::tan(0.25f * pi * (2.0f * float(i) / float(n) - 1.0f));
        const float v = std::tan(0.25f * pi * (2.0f * float(j) / float(n) - 1.0f));
        vec3 c;
        c[a] = s;
        c[(a + 1) % 3] = u * s;
        c[(a + 2) % 3] = v;
        const vec3 d = glm::normalize(c);
        m.p.push_back(centre + d * (r * (1.0f + amp * fbm(freq * d + shift))));
      }
    const auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(i * (n + 1) + j); };
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  }
}

std::shared_ptr<triangle_mesh> make_mesh() {
  auto m = std::make_shared<triangle_mesh>();
  add_sphere(*m, vec3(0.0f), 1.0f, 290, 0.08f, 3.0f, vec3(0.0f));
  pcg32 rng(2024, 7);
  for (int k = 0; k < 160; ++k) {
    vec3 c;
    do c = 2.0f * vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 1.0f;
    while (glm::dot(c, c) > 0.75f * 0.75f);
    const float r = 0.04f + 0.08f * rng.uniform();
    add_sphere(*m, c, r, 12, 0.25f, 2.5f, 10.0f * vec3(rng.uniform(), rng.uniform(), rng.uniform()));
  }
  return m;
}

// ---------------------------------------------------------------- the rays

struct segment {
  ray r;
  float tmax;
};

aabb mesh_bounds(const triangle_mesh& m) {
  aabb b;
  for (const vec3& p : m.p) b.grow(p);
  return b;
}

vec3 point_in(const aabb& b, pcg32& rng) {
  return b.lo + (b.hi - b.lo) * vec3(rng.uniform(), rng.uniform(), rng.uniform());
}

// ---------------------------------------------------------------- mcrt

struct mcrt_bare {
  bvh tree;
  std::vector<std::uint32_t> triangle_of;  // leaf order -> the mesh's triangle
  // the vertices in leaf order (in huge pages where the system has them)
  std::vector<triangle_vertices, large_array_allocator<triangle_vertices>> verts;

  explicit mcrt_bare(const triangle_mesh& m) {
    const std::size_t n = m.triangle_count();
    std::vector<aabb> bounds(n);
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) bounds[i].grow(m.p[m.indices[3 * i + std::size_t(k)]]);
    tree = bvh(bounds, triangle_leaf_width);
    triangle_of = tree.order();
    verts.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      for (int v = 0; v < 3; ++v)
        verts[k].p[std::size_t(v)] = m.p[m.indices[3 * std::size_t(triangle_of[k]) + std::size_t(v)]];
      verts[k].tag = triangle_of[k];
    }
    tree.renumber_in_order();
  }

  // t of the closest hit (infinity for none); prim its triangle.
  float closest(const ray& r, std::int64_t& prim) const {
    float tmax = infinity;
    const watertight_ray wr(r);
    triangle_hit h;
    const std::int64_t k =
        tree.closest_leaf(r, 0.0f, tmax, [&](std::uint32_t first, std::uint32_t count, float t0, float& t1) {
          const int j = closest_in_leaf(wr, t0, t1, &verts[first], int(count), h);
          return j < 0 ? std::int64_t(-1) : std::int64_t(first) + j;
        });
    prim = k < 0 ? -1 : std::int64_t(verts[std::size_t(k)].tag);
    return k < 0 ? infinity : tmax;
  }

  bool occluded(const ray& r, float tmax) const {
    const watertight_ray wr(r);
    return tree.any_leaf(r, 0.0f, tmax, [&](std::uint32_t first, std::uint32_t count, float t0, float t1) {
      return any_in_leaf(wr, t0, t1, &verts[first], int(count));
    });
  }
};

// ---------------------------------------------------------------- Embree

struct embree_config {
  const char* name;
  RTCBuildQuality quality;
  RTCSceneFlags flags;
};
constexpr std::array<embree_config, 3> embree_configs = {{
    {"MEDIUM", RTC_BUILD_QUALITY_MEDIUM, RTC_SCENE_FLAG_NONE},
    {"HIGH", RTC_BUILD_QUALITY_HIGH, RTC_SCENE_FLAG_NONE},
    {"MEDIUM+ROBUST", RTC_BUILD_QUALITY_MEDIUM, RTC_SCENE_FLAG_ROBUST},
}};

void embree_error(void*, RTCError code, const char* str) {
  std::fprintf(stderr, "Embree error %d: %s\n", int(code), str ? str : "");
  std::exit(2);
}

// A committed scene of the mesh; seconds: the time of rtcCommitScene.
RTCScene embree_scene(RTCDevice device, const triangle_mesh& m, const embree_config& c, double& seconds) {
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, c.flags);
  rtcSetSceneBuildQuality(scene, c.quality);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(geom, c.quality);
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.p.size()));
  for (std::size_t i = 0; i < m.p.size(); ++i) v[3 * i] = m.p[i].x, v[3 * i + 1] = m.p[i].y, v[3 * i + 2] = m.p[i].z;
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), m.triangle_count()));
  std::copy(m.indices.begin(), m.indices.end(), idx);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  const auto t0 = clock_type::now();
  rtcCommitScene(scene);
  seconds = seconds_since(t0);
  return scene;
}

float embree_closest(RTCScene scene, const ray& r, std::int64_t& prim) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = r.o.x, rh.ray.org_y = r.o.y, rh.ray.org_z = r.o.z;
  rh.ray.dir_x = r.d.x, rh.ray.dir_y = r.d.y, rh.ray.dir_z = r.d.z;
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = infinity;
  rh.ray.mask = ~0u;
  rh.ray.flags = 0;
  rh.ray.time = 0.0f;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
    prim = -1;
    return infinity;
  }
  prim = rh.hit.primID;
  return rh.ray.tfar;
}

bool embree_occluded(RTCScene scene, const ray& r, float tmax) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay ray;
  ray.org_x = r.o.x, ray.org_y = r.o.y, ray.org_z = r.o.z;
  ray.dir_x = r.d.x, ray.dir_y = r.d.y, ray.dir_z = r.d.z;
  ray.tnear = 0.0f;
  ray.tfar = tmax;
  ray.mask = ~0u;
  ray.flags = 0;
  ray.time = 0.0f;
  rtcOccluded1(scene, &ctx, &ray);
  return ray.tfar < 0.0f;  // -inf when blocked
}

// ---------------------------------------------------------------- runs

struct pass {
  double seconds = 0.0;
  std::size_t hits = 0;
  double checksum = 0.0;
};

template <class F>
pass run_closest(const std::vector<ray>& rays, std::vector<float>* ts, std::vector<std::int64_t>* prims, F&& f) {
  pass p;
  const auto t0 = clock_type::now();
  for (std::size_t i = 0; i < rays.size(); ++i) {
    std::int64_t prim;
    const float t = f(rays[i], prim);
    if (prim >= 0) ++p.hits, p.checksum += t;
    if (ts) (*ts)[i] = t, (*prims)[i] = prim;
  }
  p.seconds = seconds_since(t0);
  return p;
}

template <class F>
pass run_shadow(const std::vector<segment>& segs, std::vector<char>* blocked, F&& f) {
  pass p;
  const auto t0 = clock_type::now();
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const bool b = f(segs[i].r, segs[i].tmax);
    p.hits += b;
    if (blocked) (*blocked)[i] = b;
  }
  p.seconds = seconds_since(t0);
  return p;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const int build_rounds = std::min(rounds, 3);
  constexpr std::size_t ray_count = std::size_t(1) << 20;

  auto t0 = clock_type::now();
  const std::shared_ptr<triangle_mesh> mesh = make_mesh();
  const aabb box = mesh_bounds(*mesh);
  std::printf("mesh: %zu triangles, %zu vertices, bounds (%.3f %.3f %.3f) - (%.3f %.3f %.3f), made in %.2f s\n",
              mesh->triangle_count(), mesh->p.size(), box.lo.x, box.lo.y, box.lo.z, box.hi.x, box.hi.y, box.hi.z,
              seconds_since(t0));

  std::vector<ray> rays(ray_count);
  std::vector<segment> segs(ray_count);
  {
    pcg32 rng(17, 3);
    for (ray& r : rays) r = {point_in(box, rng), square_to_uniform_sphere(rng.uniform2())};
    pcg32 rng2(29, 5);
    for (segment& s : segs) {
      const vec3 a = point_in(box, rng2), b = point_in(box, rng2);
      const float len = glm::length(b - a);
      s = {{a, (b - a) / len}, len};
    }
  }

  RTCDevice device1 = rtcNewDevice("threads=1");
  RTCDevice device_all = rtcNewDevice(nullptr);
  rtcSetDeviceErrorFunction(device1, embree_error, nullptr);
  rtcSetDeviceErrorFunction(device_all, embree_error, nullptr);
  std::printf("Embree %d.%d.%d; rays: %zu closest-hit, %zu shadow; %d rounds (builds: %d), one thread for the rays\n",
              RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH, ray_count, ray_count, rounds, build_rounds);

  // ---- builds, interleaved
  std::vector<double> b_bare, b_scene;
  std::array<std::vector<double>, embree_configs.size()> b_e1, b_eall;
  std::unique_ptr<mcrt_bare> bare;
  std::unique_ptr<scene> sc;
  std::array<RTCScene, embree_configs.size()> escene{};
  for (int round = 0; round < build_rounds; ++round) {
    bare.reset();
    t0 = clock_type::now();
    bare = std::make_unique<mcrt_bare>(*mesh);
    b_bare.push_back(seconds_since(t0));
    for (std::size_t c = 0; c < embree_configs.size(); ++c) {
      if (escene[c]) rtcReleaseScene(escene[c]);
      double s;
      escene[c] = embree_scene(device1, *mesh, embree_configs[c], s);
      b_e1[c].push_back(s);
      RTCScene other = embree_scene(device_all, *mesh, embree_configs[c], s);
      b_eall[c].push_back(s);
      rtcReleaseScene(other);
    }
    sc.reset();
    sc = std::make_unique<scene>();
    sc->materials.push_back(lambertian{});
    for (const triangle& t : triangles_of(mesh)) sc->add(t, 0);
    t0 = clock_type::now();
    sc->build_accelerator();
    b_scene.push_back(seconds_since(t0));
    std::printf("build round %d: mcrt bvh %.3f s, scene.build_accelerator %.3f s", round + 1, b_bare.back(),
                b_scene.back());
    for (std::size_t c = 0; c < embree_configs.size(); ++c)
      std::printf(", Embree %s 1 thread %.3f s / default threads %.3f s", embree_configs[c].name, b_e1[c].back(),
                  b_eall[c].back());
    std::printf("\n");
  }
  {
    std::size_t leaves = 0, prims = 0;
    for (const bvh::node& nd : bare->tree.nodes()) leaves += nd.count > 0, prims += nd.count;
    std::printf("mcrt bvh: binary tree %zu nodes (%zu bytes), %zu leaves (%.2f triangles each); traversal's %d-wide "
                "tree %zu nodes (%zu bytes)\n",
                bare->tree.nodes().size(), bare->tree.nodes().size() * sizeof(bvh::node), leaves,
                double(prims) / double(leaves), bvh::width, bare->tree.wide_node_count(),
                bare->tree.wide_node_count() * 32 * std::size_t(bvh::width));
  }

  // ---- cross-check (untimed): mcrt bare and scene against Embree MEDIUM and HIGH
  bool ok = true;
  {
    std::vector<float> tm(ray_count), te(ray_count);
    std::vector<std::int64_t> pm(ray_count), pe(ray_count);
    run_closest(rays, &tm, &pm, [&](const ray& r, std::int64_t& p) { return bare->closest(r, p); });
    std::size_t scene_diff = 0;
    for (std::size_t i = 0; i < ray_count; ++i) {
      hit_record rec;
      const bool h = sc->hit(rays[i], 0.0f, infinity, rec);
      if (h != (pm[i] >= 0) || (h && rec.t != tm[i])) ++scene_diff;
    }
    std::printf("check: scene.hit against bare bvh: %zu of %zu rays differ\n", scene_diff, ray_count);
    ok = ok && scene_diff == 0;
    for (std::size_t c = 0; c < embree_configs.size(); ++c) {
      run_closest(rays, &te, &pe, [&](const ray& r, std::int64_t& p) { return embree_closest(escene[c], r, p); });
      std::size_t hits_m = 0, hits_e = 0, status = 0, prim = 0, far_t = 0;
      double max_rel = 0.0;
      for (std::size_t i = 0; i < ray_count; ++i) {
        hits_m += pm[i] >= 0;
        hits_e += pe[i] >= 0;
        if ((pm[i] >= 0) != (pe[i] >= 0)) {
          ++status;
          continue;
        }
        if (pm[i] < 0) continue;
        prim += pm[i] != pe[i];
        const double rel = std::abs(double(tm[i]) - double(te[i])) / double(te[i]);
        max_rel = std::max(max_rel, rel);
        far_t += rel > 1e-4;
      }
      std::printf("check closest vs Embree %s: hits mcrt %zu, Embree %zu; hit/miss differ %zu, triangle differs %zu, "
                  "t differs > 1e-4 %zu, max relative t difference (same triangle or not) %.2e\n",
                  embree_configs[c].name, hits_m, hits_e, status, prim, far_t, max_rel);
      ok = ok && double(status + far_t) <= 1e-4 * double(ray_count);
    }
    std::vector<char> om(ray_count), oe(ray_count);
    run_shadow(segs, &om, [&](const ray& r, float tmax) { return bare->occluded(r, tmax); });
    for (std::size_t c = 0; c < embree_configs.size(); ++c) {
      run_shadow(segs, &oe, [&](const ray& r, float tmax) { return embree_occluded(escene[c], r, tmax); });
      std::size_t bm = 0, be = 0, diff = 0;
      for (std::size_t i = 0; i < ray_count; ++i) bm += om[i], be += oe[i], diff += om[i] != oe[i];
      std::printf("check shadow vs Embree %s: blocked mcrt %zu, Embree %zu; differ %zu\n", embree_configs[c].name, bm,
                  be, diff);
      ok = ok && double(diff) <= 1e-4 * double(ray_count);
    }
  }

  // ---- rays, interleaved
  std::vector<double> c_bare, c_scene, s_bare;
  std::array<std::vector<double>, embree_configs.size()> c_e, s_e;
  double sink = 0.0;
  for (int round = 0; round < rounds; ++round) {
    pass p = run_closest(rays, nullptr, nullptr, [&](const ray& r, std::int64_t& prim) { return bare->closest(r, prim); });
    c_bare.push_back(p.seconds), sink += p.checksum;
    for (std::size_t c = 0; c < embree_configs.size(); ++c) {
      p = run_closest(rays, nullptr, nullptr,
                      [&](const ray& r, std::int64_t& prim) { return embree_closest(escene[c], r, prim); });
      c_e[c].push_back(p.seconds), sink += p.checksum;
    }
    p = run_closest(rays, nullptr, nullptr, [&](const ray& r, std::int64_t& prim) {
      hit_record rec;
      const bool h = sc->hit(r, 0.0f, infinity, rec);
      prim = h ? 0 : -1;
      return h ? rec.t + rec.p.x : infinity;
    });
    c_scene.push_back(p.seconds), sink += p.checksum;
    p = run_shadow(segs, nullptr, [&](const ray& r, float tmax) { return bare->occluded(r, tmax); });
    s_bare.push_back(p.seconds), sink += double(p.hits);
    for (std::size_t c = 0; c < embree_configs.size(); ++c) {
      p = run_shadow(segs, nullptr, [&](const ray& r, float tmax) { return embree_occluded(escene[c], r, tmax); });
      s_e[c].push_back(p.seconds), sink += double(p.hits);
    }
    const auto mr = [&](double s) { return double(ray_count) / s * 1e-6; };
    std::printf("rays round %d (Mrays/s): closest mcrt bare %.3f, scene %.3f", round + 1, mr(c_bare.back()),
                mr(c_scene.back()));
    for (std::size_t c = 0; c < embree_configs.size(); ++c)
      std::printf(", Embree %s %.3f", embree_configs[c].name, mr(c_e[c].back()));
    std::printf("; shadow mcrt %.3f", mr(s_bare.back()));
    for (std::size_t c = 0; c < embree_configs.size(); ++c)
      std::printf(", Embree %s %.3f", embree_configs[c].name, mr(s_e[c].back()));
    std::printf("\n");
  }

  // ---- summary: medians; ratios mcrt / Embree as medians of the per-round ratios
  const auto mr = [&](double s) { return double(ray_count) / s * 1e-6; };
  const auto ratio = [](const std::vector<double>& embree_s, const std::vector<double>& mcrt_s) {
    std::vector<double> r;
    for (std::size_t i = 0; i < mcrt_s.size(); ++i) r.push_back(embree_s[i] / mcrt_s[i]);
    return median(r);
  };
  std::printf("\nsummary (medians over rounds; ratio = mcrt speed / Embree speed, median of the rounds' ratios)\n");
  std::printf("build seconds: mcrt bvh %.3f, scene.build_accelerator %.3f\n", median(b_bare), median(b_scene));
  for (std::size_t c = 0; c < embree_configs.size(); ++c)
    std::printf("build seconds: Embree %-13s 1 thread %.3f (mcrt/Embree speed %.3f), default threads %.3f (%.3f)\n",
                embree_configs[c].name, median(b_e1[c]), ratio(b_e1[c], b_bare), median(b_eall[c]),
                ratio(b_eall[c], b_bare));
  std::printf("closest Mrays/s: mcrt bare %.3f, scene %.3f\n", mr(median(c_bare)), mr(median(c_scene)));
  for (std::size_t c = 0; c < embree_configs.size(); ++c)
    std::printf("closest Mrays/s: Embree %-13s %.3f; ratio bare %.3f, scene %.3f\n", embree_configs[c].name,
                mr(median(c_e[c])), ratio(c_e[c], c_bare), ratio(c_e[c], c_scene));
  std::printf("shadow Mrays/s: mcrt bare %.3f\n", mr(median(s_bare)));
  for (std::size_t c = 0; c < embree_configs.size(); ++c)
    std::printf("shadow Mrays/s: Embree %-13s %.3f; ratio %.3f\n", embree_configs[c].name, mr(median(s_e[c])),
                ratio(s_e[c], s_bare));
  std::printf("(checksum %.6g)\n", sink);

  for (RTCScene s : escene) rtcReleaseScene(s);
  rtcReleaseDevice(device1);
  rtcReleaseDevice(device_all);
  if (!ok) std::printf("CHECK FAILED: mcrt and Embree disagree on more than 1e-4 of the rays\n");
  return ok ? 0 : 1;
}
