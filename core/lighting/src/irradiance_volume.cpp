#include "lumar/lighting/irradiance_volume.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/base/latlong.h"
#include "lumar/base/octahedral.h"
#include "lumar/base/sphere_directions.h"
#include "lumar/lighting/sh.h"

namespace lumar {

namespace {

constexpr double kDepthSharpness = 20.0;  // cosine power that spreads ray distances over moment texels

struct Contribution {
  glm::dvec3 direction;
  glm::dvec3 power;  // radiance x solid angle
};

}  // namespace

std::string VolumeSettings::describe() const {
  std::string s = storage == ProbeStorage::sh9          ? "sh9"
                  : storage == ProbeStorage::octahedral ? "oct" + std::to_string(octahedral_resolution)
                                                        : "sh9+oct" + std::to_string(octahedral_resolution);
  if (separate_lights) s += "+lights";
  if (separate_lights && shadow_map_resolution != VolumeSettings{}.shadow_map_resolution)
    s += " (shadow maps " + std::to_string(shadow_map_resolution) + " px)";
  s += ", " + std::to_string(rays_per_probe) + " rays";
  if (radiance.bright_fraction <= 0.0) s += ", no bright texels";
  s += ", spacing " + std::to_string(spacing).substr(0, 4) + (refine ? " + refined" : "");
  if (!visibility) s += ", no visibility";
  return s;
}

VolumeSettings volume_settings_for(const std::string& method) {
  VolumeSettings s;
  if (method == "volume" || method.empty()) return s;
  if (method == "sh9") {
    s.storage = ProbeStorage::sh9;
    s.separate_lights = false;
  } else if (method == "octahedral") {
    s.storage = ProbeStorage::octahedral;
    s.octahedral_resolution = 16;
    s.separate_lights = false;
  } else if (method == "lights") {
    s.storage = ProbeStorage::sh9;
    s.separate_lights = true;
  } else if (method == "greger2004") {
    s.storage = ProbeStorage::octahedral;
    s.octahedral_resolution = 8;
    s.separate_lights = false;
    s.rays_per_probe = 64;
    s.radiance.bright_fraction = 0.0;
    s.radiance.max_lights = 0;
    s.visibility = false;
  } else {
    throw InputError("irradiance method '" + method +
                     "' is unknown; use reference, volume, sh9, octahedral, lights or greger2004");
  }
  return s;
}

int IrradianceVolume::atlas_height(int n) const {
  const int count = std::max<int>(1, int(probes.size()));
  return ((count + atlas_columns - 1) / atlas_columns) * (n + 2);
}

namespace {

// Bilinear sample of an atlas block (DDGI layout) at octahedral coordinates e.
template <int C>
std::array<double, C> sample_block(const std::vector<float>& atlas, int width, int n, int columns, int probe,
                                   const glm::dvec2& e) {
  const int bx = (probe % columns) * (n + 2), by = (probe / columns) * (n + 2);
  const double x = 1.0 + (e.x * 0.5 + 0.5) * n - 0.5, y = 1.0 + (e.y * 0.5 + 0.5) * n - 0.5;
  const int x0 = std::clamp(int(std::floor(x)), 0, n), y0 = std::clamp(int(std::floor(y)), 0, n);
  const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
  std::array<double, C> out{};
  const double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  const int dx[4] = {0, 1, 0, 1}, dy[4] = {0, 0, 1, 1};
  for (int k = 0; k < 4; ++k) {
    const float* t = &atlas[(std::size_t(by + y0 + dy[k]) * width + (bx + x0 + dx[k])) * C];
    for (int c = 0; c < C; ++c) out[std::size_t(c)] += w[k] * t[c];
  }
  return out;
}

// Writes an N x N map (row j, column i) into probe's block with its border.
template <int C>
void write_block(std::vector<float>& atlas, int width, int n, int columns, int probe, const std::vector<float>& map) {
  const int bx = (probe % columns) * (n + 2), by = (probe / columns) * (n + 2);
  for (int y = 0; y < n + 2; ++y)
    for (int x = 0; x < n + 2; ++x) {
      const glm::ivec2 s = octahedral_border_source(x, y, n);
      const float* src = &map[(std::size_t(s.y) * n + s.x) * C];
      float* dst = &atlas[(std::size_t(by + y) * width + (bx + x)) * C];
      for (int c = 0; c < C; ++c) dst[c] = src[c];
    }
}

double light_solid_angle(const VolumeLight& l, const glm::dvec3& capture, const glm::dvec3& p, glm::dvec3* toward) {
  if (!l.on_proxy) {
    *toward = l.direction;
    return l.solid_angle;
  }
  return patch_solid_angle_from(p, capture, l.position, l.normal, l.solid_angle, toward);
}

// Everything one probe needs while the volume is built.
struct ProbeBuilder {
  const RoomRadiance& radiance;
  const VolumeSettings& settings;
  std::vector<glm::dvec3> ray_directions, quick_directions, irradiance_directions, depth_directions;
  std::vector<Contribution> distant_dim;  // distant map: every dim texel
  double max_depth = 1.0;

  ProbeBuilder(const RoomRadiance& r, const VolumeSettings& s) : radiance(r), settings(s) {
    ray_directions = fibonacci_directions(s.rays_per_probe);
    quick_directions = fibonacci_directions(64);
    const int n = s.octahedral_resolution;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) irradiance_directions.push_back(octahedral_texel_direction(i, j, n));
    const int d = s.depth_resolution;
    for (int j = 0; j < d; ++j)
      for (int i = 0; i < d; ++i) depth_directions.push_back(octahedral_texel_direction(i, j, d));
    if (r.distant()) {
      const EnvironmentMap& m = r.working_map();
      for (int row = 0; row < m.height; ++row) {
        const double omega = latlong_pixel_solid_angle(row, m.width, m.height);
        for (int col = 0; col < m.width; ++col) {
          if (r.is_bright(col, row)) continue;
          distant_dim.push_back(
              {glm::normalize(m.world_direction(latlong_pixel_direction(col, row, m.width, m.height))),
               glm::dvec3(m.texel(col, row)) * omega});
        }
      }
    }
  }

  // Back faces seen and the nearest hit, from a few rays. Each starts a little behind p:
  // a ray that starts exactly on a plane may pass through it, so a lattice node on the
  // floor looked clear, kept its place, and its lower half saw through the floor.
  void quick_test(const glm::dvec3& p, int* back, double* nearest) const {
    constexpr double kBehind = 1e-4;  // metres
    *back = 0;
    *nearest = std::numeric_limits<double>::infinity();
    const RayScene& rays = *radiance.ray_scene();
    for (const glm::dvec3& w : quick_directions) {
      Ray ray;
      ray.origin = glm::vec3(p - w * kBehind);
      ray.direction = glm::vec3(w);
      const auto hit = rays.intersect(ray);
      if (!hit) continue;
      *nearest = std::min(*nearest, std::max(0.0, double(hit->t) - kBehind));
      if (hit->back_face) ++*back;
    }
  }

  // Moves p out of geometry or away from a touching surface. False: nowhere to go.
  bool place(glm::dvec3& p, double step, bool* moved) const {
    *moved = false;
    int back = 0;
    double nearest = 0.0;
    quick_test(p, &back, &nearest);
    const double clearance = 0.1 * step;
    if (back == 0 && nearest >= clearance) return true;
    const bool inside = back > int(quick_directions.size()) / 5;
    for (double scale : {0.25, 0.45}) {
      glm::dvec3 best(0.0);
      double best_nearest = -1.0;
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            if (!dx && !dy && !dz) continue;
            const glm::dvec3 q = p + glm::normalize(glm::dvec3(dx, dy, dz)) * (scale * step);
            int b = 0;
            double nq = 0.0;
            quick_test(q, &b, &nq);
            if (b == 0 && nq >= clearance && nq > best_nearest) best = q, best_nearest = nq;
          }
      if (best_nearest > 0.0) {
        p = best;
        *moved = true;
        return true;
      }
    }
    return !inside;
  }

  struct Result {
    std::vector<float> irradiance;  // n*n RGB
    std::array<float, 27> sh{};
    std::vector<float> depth;  // d*d RG
    std::vector<float> light_visibility;
  };

  Result compute(const glm::dvec3& p) const {
    Result out;
    std::vector<Contribution> contributions;
    std::vector<double> distances;
    if (radiance.distant()) {
      contributions = distant_dim;
    } else {
      const double weight = 4.0 * kPi / double(ray_directions.size());
      contributions.reserve(ray_directions.size() + radiance.bright_texels().size());
      distances.reserve(ray_directions.size());
      for (const glm::dvec3& w : ray_directions) {
        const RoomRadiance::Sample s = radiance.dim_radiance(p, w);
        contributions.push_back({w, s.radiance * weight});
        distances.push_back(std::min(s.distance, max_depth));
      }
    }
    // Bright texels: exact, each with its visibility; lights kept apart when separate.
    const auto& bright = radiance.bright_texels();
    std::vector<std::uint8_t> visible(bright.size(), 1);
    for (std::size_t t = 0; t < bright.size(); ++t) {
      const BrightTexel& b = bright[t];
      glm::dvec3 toward;
      const double omega =
          radiance.solid_angle_from(p, b.on_proxy, b.position, b.normal, b.direction, b.solid_angle, &toward);
      visible[t] = omega > 0.0 && radiance.sees(p, b.on_proxy, b.position, b.direction);
      if (settings.separate_lights && b.light >= 0) continue;
      if (visible[t]) contributions.push_back({toward, b.radiance * omega});
    }
    if (settings.separate_lights) {
      out.light_visibility.assign(radiance.lights().size(), 0.0f);
      for (std::size_t l = 0; l < radiance.lights().size(); ++l) {
        // Weighted by power; a light that is out (relit to black) by solid angle, so that
        // it keeps its shadow and fades in again like the others.
        double seen = 0.0, total = 0.0, seen_omega = 0.0, total_omega = 0.0;
        for (int t : radiance.lights()[l].texels) {
          const double omega = bright[std::size_t(t)].solid_angle;
          const double w = luminance(bright[std::size_t(t)].radiance) * omega;
          total += w, total_omega += omega;
          if (visible[std::size_t(t)]) seen += w, seen_omega += omega;
        }
        out.light_visibility[l] = total > 0.0         ? float(seen / total)
                                  : total_omega > 0.0 ? float(seen_omega / total_omega)
                                                      : 0.0f;
      }
    }

    if (settings.storage != ProbeStorage::octahedral) {
      std::array<glm::dvec3, 9> coefficients{};
      for (const Contribution& c : contributions) {
        const auto y = sh9_basis(c.direction);
        for (int i = 0; i < 9; ++i) coefficients[std::size_t(i)] += c.power * y[std::size_t(i)];
      }
      for (int i = 0; i < 9; ++i)
        for (int ch = 0; ch < 3; ++ch) out.sh[std::size_t(i * 3 + ch)] = float(coefficients[std::size_t(i)][ch]);
    }
    if (settings.storage != ProbeStorage::sh9) {
      SH9 sh9;
      for (int i = 0; i < 9; ++i)
        sh9.coefficients[std::size_t(i)] =
            glm::dvec3(out.sh[std::size_t(i * 3)], out.sh[std::size_t(i * 3 + 1)], out.sh[std::size_t(i * 3 + 2)]);
      const bool delta = settings.storage == ProbeStorage::sh9_octahedral;
      out.irradiance.assign(irradiance_directions.size() * 3, 0.0f);
      for (std::size_t k = 0; k < irradiance_directions.size(); ++k) {
        glm::dvec3 e(0.0);
        for (const Contribution& c : contributions) {
          const double cosine = glm::dot(irradiance_directions[k], c.direction);
          if (cosine > 0.0) e += c.power * cosine;
        }
        if (delta) e -= sh9_irradiance(sh9, irradiance_directions[k]);
        for (int ch = 0; ch < 3; ++ch) out.irradiance[k * 3 + std::size_t(ch)] = float(e[ch]);
      }
    }

    if (!distances.empty()) {
      out.depth.assign(depth_directions.size() * 2, 0.0f);
      for (std::size_t k = 0; k < depth_directions.size(); ++k) {
        double sw = 0.0, s1 = 0.0, s2 = 0.0, best = -2.0, best_t = max_depth;
        for (std::size_t j = 0; j < ray_directions.size(); ++j) {
          const double cosine = glm::dot(depth_directions[k], ray_directions[j]);
          if (cosine > best) best = cosine, best_t = distances[j];
          if (cosine <= 0.0) continue;
          const double c2 = cosine * cosine, c4 = c2 * c2, c16 = c4 * c4 * c4 * c4;
          const double w = c16 * c4;  // cosine^kDepthSharpness
          sw += w, s1 += w * distances[j], s2 += w * distances[j] * distances[j];
        }
        out.depth[k * 2] = float(sw > 1e-12 ? s1 / sw : best_t);
        out.depth[k * 2 + 1] = float(sw > 1e-12 ? s2 / sw : best_t * best_t);
      }
    }
    return out;
  }
};

}  // namespace

IrradianceVolume IrradianceVolume::build_distant(const RoomRadiance& radiance, const VolumeSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  IrradianceVolume v;
  v.settings_ = settings;
  v.distant_ = true;
  v.probes = {glm::vec4(0, 0, 0, 1)};
  v.node_probe = {{0, -1, -1, -1}};
  v.node_weight = {{1, 0, 0, 0}};
  v.refined = {0};
  v.irradiance_n = settings.octahedral_resolution;
  v.depth_n = settings.depth_resolution;
  ProbeBuilder builder(radiance, settings);
  const auto r = builder.compute(glm::dvec3(0.0));
  if (settings.storage != ProbeStorage::sh9) {
    v.irradiance_atlas.assign(std::size_t(v.atlas_width(v.irradiance_n)) * v.atlas_height(v.irradiance_n) * 3, 0.0f);
    write_block<3>(v.irradiance_atlas, v.atlas_width(v.irradiance_n), v.irradiance_n, 1, 0, r.irradiance);
  }
  if (settings.storage != ProbeStorage::octahedral) v.sh.assign(r.sh.begin(), r.sh.end());
  v.depth_atlas.assign(std::size_t(v.atlas_width(v.depth_n)) * v.atlas_height(v.depth_n) * 2, 1e6f);
  if (settings.separate_lights)
    for (const DominantLight& l : radiance.lights()) {
      v.lights.push_back({l.power / l.solid_angle, l.solid_angle, l.direction, false, {}, {}});
      v.light_visibility.push_back(1.0f);
    }
  v.stats_.probes = 1;
  v.stats_.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  v.stats_.bytes = (v.irradiance_atlas.size() + v.sh.size()) * sizeof(float) + v.lights.size() * 64;
  return v;
}

IrradianceVolume IrradianceVolume::build(const RoomRadiance& radiance, const glm::dvec3& box_min,
                                         const glm::dvec3& box_max, const VolumeSettings& settings) {
  if (radiance.distant()) return build_distant(radiance, settings);
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t rays_before = radiance.traced_rays(), fallback_before = radiance.fallback_rays();
  IrradianceVolume v;
  v.settings_ = settings;
  v.box_min = glm::min(box_min, box_max);
  v.box_max = glm::max(box_max, glm::max(box_min, box_max) + 1e-3);
  v.capture_position = radiance.working_map().capture_position;
  const glm::dvec3 extent = v.box_max - v.box_min;
  for (int a = 0; a < 3; ++a)
    v.cells[a] = std::max(2, int(std::ceil(extent[a] / std::max(settings.spacing, 1e-3) - 1e-9)));
  v.cell_size = extent / glm::dvec3(v.cells);
  const glm::ivec3 C = v.cells;
  const auto cell_index = [&](int x, int y, int z) { return (std::size_t(z) * C.y + y) * C.x + x; };

  // Refine cells that proxy triangles come near (half a cell around the cell).
  v.refined.assign(std::size_t(C.x) * C.y * C.z, 0);
  const Mesh& proxy = radiance.proxy();
  if (settings.refine) {
    for (int z = 0; z < C.z; ++z)
      for (int y = 0; y < C.y; ++y)
        for (int x = 0; x < C.x; ++x) {
          const glm::dvec3 lo = v.box_min + glm::dvec3(x, y, z) * v.cell_size - 0.5 * v.cell_size;
          const glm::dvec3 hi = lo + 2.0 * v.cell_size;
          for (std::size_t t = 0; t < proxy.triangle_count(); ++t) {
            glm::dvec3 tmin(1e30), tmax(-1e30);
            for (int k = 0; k < 3; ++k) {
              const glm::dvec3 q(proxy.positions[proxy.indices[t * 3 + std::size_t(k)]]);
              tmin = glm::min(tmin, q), tmax = glm::max(tmax, q);
            }
            if (glm::all(glm::lessThanEqual(tmin, hi)) && glm::all(glm::greaterThanEqual(tmax, lo))) {
              v.refined[cell_index(x, y, z)] = 1;
              break;
            }
          }
        }
  }

  // Fine lattice: real probes and the blends that stand for hanging nodes.
  const glm::ivec3 F = 2 * C + 1;
  const auto node_index = [&](int x, int y, int z) { return (std::size_t(z) * F.y + y) * F.x + x; };
  std::vector<int> node_to_probe(std::size_t(F.x) * F.y * F.z, -1);
  std::vector<glm::dvec3> lattice_positions;
  const auto is_real = [&](const glm::ivec3& I) {
    if (I.x % 2 == 0 && I.y % 2 == 0 && I.z % 2 == 0) return true;
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      if (I[a] % 2)
        lo[a] = hi[a] = (I[a] - 1) / 2;
      else
        lo[a] = std::max(0, I[a] / 2 - 1), hi[a] = std::min(C[a] - 1, I[a] / 2);
    }
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x)
          if (!v.refined[cell_index(x, y, z)]) return false;
    return true;
  };
  for (int z = 0; z < F.z; ++z)
    for (int y = 0; y < F.y; ++y)
      for (int x = 0; x < F.x; ++x)
        if (is_real({x, y, z})) {
          node_to_probe[node_index(x, y, z)] = int(lattice_positions.size());
          lattice_positions.push_back(v.box_min + glm::dvec3(x, y, z) * 0.5 * v.cell_size);
        }
  v.node_probe.assign(node_to_probe.size(), {-1, -1, -1, -1});
  v.node_weight.assign(node_to_probe.size(), {0, 0, 0, 0});
  for (int z = 0; z < F.z; ++z)
    for (int y = 0; y < F.y; ++y)
      for (int x = 0; x < F.x; ++x) {
        const std::size_t i = node_index(x, y, z);
        if (node_to_probe[i] >= 0) {
          v.node_probe[i] = {node_to_probe[i], -1, -1, -1};
          v.node_weight[i] = {1, 0, 0, 0};
          continue;
        }
        const glm::ivec3 I(x, y, z);
        int odd = 0;
        for (int a = 0; a < 3; ++a) odd += I[a] % 2;
        if (odd == 3) continue;  // centre of an unsplit cell: never a corner
        // Linear blend of the even neighbours along each odd axis.
        int count = 0;
        for (int corner = 0; corner < 8; ++corner) {
          glm::ivec3 J = I;
          bool valid = true;
          for (int a = 0; a < 3; ++a) {
            const int bit = (corner >> a) & 1;
            if (I[a] % 2)
              J[a] = I[a] - 1 + 2 * bit;
            else if (bit)
              valid = false;
          }
          if (!valid) continue;
          v.node_probe[i][std::size_t(count)] = node_to_probe[node_index(J.x, J.y, J.z)];
          v.node_weight[i][std::size_t(count)] = float(1.0 / double(1 << odd));
          ++count;
        }
      }

  // Probes: placed, then traced in parallel.
  const int P = int(lattice_positions.size());
  const double step = 0.5 * std::min({v.cell_size.x, v.cell_size.y, v.cell_size.z});
  v.normal_bias = 0.15 * step;
  ProbeBuilder builder(radiance, settings);
  builder.max_depth = 2.0 * glm::length(v.cell_size);
  std::vector<glm::dvec3> positions = lattice_positions;
  std::vector<std::uint8_t> enabled(std::size_t(P), 1), moved(std::size_t(P), 0);
  std::vector<ProbeBuilder::Result> results{std::size_t(P)};
  tbb::parallel_for(0, P, [&](int k) {
    bool m = false;
    enabled[std::size_t(k)] = builder.place(positions[std::size_t(k)], step, &m);
    moved[std::size_t(k)] = m;
    if (enabled[std::size_t(k)]) results[std::size_t(k)] = builder.compute(positions[std::size_t(k)]);
  });

  v.irradiance_n = settings.octahedral_resolution;
  v.depth_n = settings.depth_resolution;
  v.atlas_columns = std::max(1, int(std::ceil(std::sqrt(double(P)))));
  v.probes.resize(std::size_t(P));
  if (settings.storage != ProbeStorage::sh9)
    v.irradiance_atlas.assign(std::size_t(v.atlas_width(v.irradiance_n)) * v.atlas_height(v.irradiance_n) * 3, 0.0f);
  if (settings.storage != ProbeStorage::octahedral) v.sh.assign(std::size_t(P) * 27, 0.0f);
  v.depth_atlas.assign(std::size_t(v.atlas_width(v.depth_n)) * v.atlas_height(v.depth_n) * 2, 0.0f);
  if (settings.separate_lights)
    for (const DominantLight& l : radiance.lights())
      v.lights.push_back({l.power / l.solid_angle, l.solid_angle, l.direction, l.on_proxy, l.position, l.normal});
  v.light_visibility.assign(std::size_t(P) * v.lights.size(), 0.0f);
  if (settings.separate_lights && !v.lights.empty()) {
    const int n = std::max(2, settings.shadow_map_resolution);
    v.shadow_n = n;
    v.light_shadow.assign(std::size_t(n) * n * v.lights.size(), 0.0f);
    const RayScene& rays = *radiance.ray_scene();
    tbb::parallel_for(0, int(v.lights.size()) * n, [&](int job) {
      const std::size_t l = std::size_t(job / n);
      const int j = job % n;
      const VolumeLight& light = v.lights[l];
      if (!light.on_proxy) return;
      for (int i = 0; i < n; ++i) {
        const glm::dvec3 d = octahedral_texel_direction(i, j, n);
        float depth = 0.0f;  // behind the light's surface: never lit
        if (glm::dot(d, light.normal) > 0.0) {
          Ray ray;
          ray.origin = glm::vec3(light.position + light.normal * 1e-3);
          ray.direction = glm::vec3(d);
          const auto hit = rays.intersect(ray);
          depth = hit ? float(hit->t) : 1e6f;
        }
        v.light_shadow[(l * std::size_t(n) + std::size_t(j)) * std::size_t(n) + std::size_t(i)] = depth;
      }
    });
  }
  for (int k = 0; k < P; ++k) {
    const auto& r = results[std::size_t(k)];
    v.probes[std::size_t(k)] = glm::vec4(glm::vec3(positions[std::size_t(k)]), enabled[std::size_t(k)] ? 1.0f : 0.0f);
    v.stats_.disabled += !enabled[std::size_t(k)];
    v.stats_.moved += moved[std::size_t(k)];
    if (!enabled[std::size_t(k)]) continue;
    if (settings.storage != ProbeStorage::sh9)
      write_block<3>(v.irradiance_atlas, v.atlas_width(v.irradiance_n), v.irradiance_n, v.atlas_columns, k,
                     r.irradiance);
    if (settings.storage != ProbeStorage::octahedral)
      std::copy(r.sh.begin(), r.sh.end(), v.sh.begin() + std::ptrdiff_t(k) * 27);
    write_block<2>(v.depth_atlas, v.atlas_width(v.depth_n), v.depth_n, v.atlas_columns, k, r.depth);
    for (std::size_t l = 0; l < v.lights.size(); ++l)
      v.light_visibility[std::size_t(k) * v.lights.size() + l] = r.light_visibility[l];
  }
  v.stats_.probes = P;
  v.stats_.cells = C.x * C.y * C.z;
  v.stats_.refined_cells = int(std::count(v.refined.begin(), v.refined.end(), 1));
  v.stats_.rays = radiance.traced_rays() - rays_before;
  v.stats_.fallback_rays = radiance.fallback_rays() - fallback_before;
  v.stats_.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  v.stats_.bytes = (v.irradiance_atlas.size() + v.sh.size() + v.depth_atlas.size() + v.light_visibility.size() +
                    v.light_shadow.size() + v.probes.size() * 4 + v.node_probe.size() * 8 + v.refined.size()) *
                   sizeof(float);
  return v;
}

double IrradianceVolume::light_shadow_visibility(std::size_t l, const glm::dvec3& p) const {
  const VolumeLight& light = lights[l];
  if (shadow_n <= 0 || !light.on_proxy) return 1.0;
  const glm::dvec3 v = p - light.position;
  const double r = glm::length(v);
  if (r < 1e-9) return 1.0;
  const int n = shadow_n;
  const glm::dvec2 e = octahedral_encode(v / r);
  const double x = (e.x * 0.5 + 0.5) * n - 0.5, y = (e.y * 0.5 + 0.5) * n - 0.5;
  const int x0 = std::clamp(int(std::floor(x)), 0, n - 2), y0 = std::clamp(int(std::floor(y)), 0, n - 2);
  const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
  // Bias grows with distance: neighbouring texels' rays meet a surface at other depths.
  const double limit = r - 0.02 - 0.02 * r;
  const float* map = &light_shadow[l * std::size_t(n) * std::size_t(n)];
  const auto lit = [&](int i, int j) {
    return map[std::size_t(j) * std::size_t(n) + std::size_t(i)] >= limit ? 1.0 : 0.0;
  };
  return (1 - fy) * ((1 - fx) * lit(x0, y0) + fx * lit(x0 + 1, y0)) +
         fy * ((1 - fx) * lit(x0, y0 + 1) + fx * lit(x0 + 1, y0 + 1));
}

IrradianceVolume IrradianceVolume::blend(const IrradianceVolume& from, const IrradianceVolume& to, double t) {
  if (from.probes.size() != to.probes.size() || from.irradiance_atlas.size() != to.irradiance_atlas.size() ||
      from.sh.size() != to.sh.size() || from.lights.size() != to.lights.size() || from.distant_ != to.distant_)
    throw RuntimeError("irradiance volume: cannot blend volumes of different layouts; relight the same room");
  IrradianceVolume out = to;
  const float a = float(1.0 - t), b = float(t);
  for (std::size_t i = 0; i < out.irradiance_atlas.size(); ++i)
    out.irradiance_atlas[i] = a * from.irradiance_atlas[i] + b * to.irradiance_atlas[i];
  for (std::size_t i = 0; i < out.sh.size(); ++i) out.sh[i] = a * from.sh[i] + b * to.sh[i];
  for (std::size_t l = 0; l < out.lights.size(); ++l)
    out.lights[l].radiance = (1.0 - t) * from.lights[l].radiance + t * to.lights[l].radiance;
  for (std::size_t i = 0; i < out.light_visibility.size() && i < from.light_visibility.size(); ++i)
    out.light_visibility[i] = a * from.light_visibility[i] + b * to.light_visibility[i];
  return out;
}

glm::dvec3 light_irradiance(const VolumeLight& l, const glm::dvec3& capture, const glm::dvec3& p, const glm::dvec3& n,
                            glm::dvec3* toward) {
  const double omega = light_solid_angle(l, capture, p, toward);
  const double cosine = glm::dot(n, *toward);
  return omega > 0.0 && cosine > 0.0 ? l.radiance * omega * cosine : glm::dvec3(0.0);
}

glm::dvec3 IrradianceVolume::evaluate(const glm::dvec3& p, const glm::dvec3& normal, const glm::dvec3& normal_lights,
                                      double rest_scale, double lights_scale) const {
  const glm::dvec3 n = glm::normalize(normal), n_lights = glm::normalize(normal_lights);
  const auto probe_irradiance = [&](int k) -> glm::dvec3 {
    glm::dvec3 e(0.0);
    if (settings_.storage != ProbeStorage::octahedral) {
      SH9 sh9;
      for (int i = 0; i < 9; ++i)
        sh9.coefficients[std::size_t(i)] =
            glm::dvec3(sh[std::size_t(k) * 27 + std::size_t(i) * 3], sh[std::size_t(k) * 27 + std::size_t(i) * 3 + 1],
                       sh[std::size_t(k) * 27 + std::size_t(i) * 3 + 2]);
      e = sh9_irradiance(sh9, n);
    }
    if (settings_.storage != ProbeStorage::sh9) {
      const auto s = sample_block<3>(irradiance_atlas, atlas_width(irradiance_n), irradiance_n, atlas_columns, k,
                                     octahedral_encode(n));
      e += glm::dvec3(s[0], s[1], s[2]);
    }
    // Nine coefficients ring below zero opposite a bright source; light is never negative.
    return glm::max(e, glm::dvec3(0.0));
  };
  const std::size_t L = lights.size();
  std::vector<double> light_weight(L, 0.0);
  glm::dvec3 sum(0.0);
  double total = 0.0;
  if (distant_) {
    sum = probe_irradiance(0);
    total = 1.0;
    for (std::size_t l = 0; l < L; ++l) light_weight[l] = light_visibility[l];
  } else {
    const glm::dvec3 local = glm::clamp((p - box_min) / cell_size, glm::dvec3(0.0), glm::dvec3(cells) - 1e-9);
    const glm::ivec3 cell = glm::clamp(glm::ivec3(glm::floor(local)), glm::ivec3(0), cells - 1);
    glm::dvec3 t = local - glm::dvec3(cell);
    glm::ivec3 base = 2 * cell;
    int stride = 2;
    if (refined[(std::size_t(cell.z) * cells.y + cell.y) * cells.x + cell.x]) {
      const glm::ivec3 half = glm::ivec3(glm::greaterThanEqual(t, glm::dvec3(0.5)));
      base += half;
      t = t * 2.0 - glm::dvec3(half);
      stride = 1;
    }
    const glm::ivec3 F = 2 * cells + 1;
    const glm::dvec3 biased = p + n * normal_bias;
    for (int corner = 0; corner < 8; ++corner) {
      const glm::ivec3 o((corner & 1), (corner >> 1) & 1, (corner >> 2) & 1);
      const glm::ivec3 I = base + o * stride;
      const double tri = (o.x ? t.x : 1 - t.x) * (o.y ? t.y : 1 - t.y) * (o.z ? t.z : 1 - t.z);
      if (tri <= 0.0) continue;
      const std::size_t node = (std::size_t(I.z) * F.y + I.y) * F.x + I.x;
      for (int e = 0; e < 4; ++e) {
        const int k = node_probe[node][std::size_t(e)];
        if (k < 0 || probes[std::size_t(k)].w == 0.0f) continue;
        double w = tri * node_weight[node][std::size_t(e)];
        if (settings_.visibility) {
          const glm::dvec3 probe(probes[std::size_t(k)]);
          const glm::dvec3 to_probe = probe - p;
          const double d = glm::length(to_probe);
          double vis = d > 1e-9 ? glm::dot(to_probe / d, n) * 0.5 + 0.5 : 1.0;
          vis = vis * vis + 0.2;
          const glm::dvec3 from_probe = biased - probe;
          const double r = glm::length(from_probe);
          if (r > 1e-9) {
            const auto m = sample_block<2>(depth_atlas, atlas_width(depth_n), depth_n, atlas_columns, k,
                                           octahedral_encode(from_probe / r));
            if (r > m[0]) {
              const double variance = std::abs(m[1] - m[0] * m[0]);
              double chebyshev = variance / (variance + (r - m[0]) * (r - m[0]));
              chebyshev = std::max(chebyshev * chebyshev * chebyshev, 0.0);
              vis *= chebyshev;
            }
          }
          vis = std::max(vis, 1e-6);
          if (vis < 0.2) vis *= vis * vis / 0.04;  // crush small weights (DDGI)
          w *= vis;
        }
        sum += w * probe_irradiance(k);
        for (std::size_t l = 0; l < L; ++l)
          if (shadow_n == 0 || !lights[l].on_proxy)  // else its shadow map decides
            light_weight[l] += w * light_visibility[std::size_t(k) * L + l];
        total += w;
      }
    }
  }
  if (total <= 0.0) return glm::dvec3(0.0);
  glm::dvec3 exact(0.0);
  for (std::size_t l = 0; l < L; ++l) {
    const bool mapped = shadow_n > 0 && lights[l].on_proxy;
    const double visibility = mapped ? light_shadow_visibility(l, p) : light_weight[l] / total;
    if (visibility <= 0.0) continue;
    glm::dvec3 toward;
    exact += visibility * light_irradiance(lights[l], capture_position, p, n_lights, &toward);
  }
  return rest_scale * (sum / total) + lights_scale * exact;
}

}  // namespace lumar
