#include "lumar/lighting/room_radiance.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/base/latlong.h"

namespace lumar {

namespace {

// Where the map's texels along `t.direction` came from: the proxy point the capture point
// sees that way (a BrightTexel or a DominantLight). Left at infinity if the ray escapes.
template <class Seen>
void place_on_proxy(const RayScene* rays, const glm::dvec3& capture_position, Seen& t) {
  if (!rays) return;
  Ray ray;
  ray.origin = glm::vec3(capture_position);
  ray.direction = glm::vec3(t.direction);
  if (const auto hit = rays->intersect(ray)) {
    t.on_proxy = true;
    t.position = capture_position + t.direction * double(hit->t);
    t.normal = glm::dvec3(hit->normal);
  }
}
}  // namespace

EnvironmentMap downsample_environment_map(const EnvironmentMap& map, int height) {
  if (height <= 0 || height >= map.height || map.height % height != 0) return map;
  const int f = map.height / height;
  EnvironmentMap out;
  out.width = map.width / f;
  out.height = height;
  out.capture_position = map.capture_position;
  out.azimuth_offset_deg = map.azimuth_offset_deg;
  out.rgb.assign(std::size_t(out.width) * out.height * 3, 0.0f);
  for (int R = 0; R < out.height; ++R) {
    double total = 0.0;
    for (int r = R * f; r < (R + 1) * f; ++r) total += latlong_pixel_solid_angle(r, map.width, map.height) * f;
    for (int C = 0; C < out.width; ++C) {
      glm::dvec3 sum(0.0);
      for (int r = R * f; r < (R + 1) * f; ++r) {
        const double w = latlong_pixel_solid_angle(r, map.width, map.height);
        for (int c = C * f; c < (C + 1) * f; ++c) sum += glm::dvec3(map.texel(c, r)) * w;
      }
      const glm::dvec3 L = sum / total;
      float* p = &out.rgb[(std::size_t(R) * out.width + C) * 3];
      p[0] = float(L.r), p[1] = float(L.g), p[2] = float(L.b);
    }
  }
  return out;
}

RoomRadiance::RoomRadiance(const EnvironmentMap& map, const RadianceSettings& settings) : settings_(settings) {
  prepare(map);
}

RoomRadiance::RoomRadiance(const EnvironmentMap& map, const Mesh& proxy_world, const RadianceSettings& settings)
    : settings_(settings), proxy_(proxy_world) {
  if (proxy_.triangle_count() == 0)
    throw InputError("room radiance: the proxy model has no triangles; give a room mesh or declare the map distant");
  rays_ = std::make_unique<RayScene>();
  rays_->add_static(proxy_);
  rays_->commit();
  prepare(map);
}

RoomRadiance::RoomRadiance(const RoomRadiance& like, const EnvironmentMap& map)
    : settings_(like.settings_),
      map_(downsample_environment_map(map, like.settings_.map_height)),
      proxy_(like.proxy_),
      bright_(like.bright_),
      bright_index_(like.bright_index_),
      lights_(like.lights_),
      threshold_(like.threshold_) {
  if (map_.width != like.map_.width || map_.height != like.map_.height)
    throw InputError("room radiance: a relit map must have the size of the map it relights (" +
                     std::to_string(like.map_.width) + "x" + std::to_string(like.map_.height) + " after filtering)");
  if (like.rays_) {
    rays_ = std::make_unique<RayScene>();
    rays_->add_static(proxy_);
    rays_->commit();
  }
  for (std::size_t i = 0; i < bright_index_.size(); ++i)
    if (const int k = bright_index_[i]; k >= 0)
      bright_[std::size_t(k)].radiance =
          glm::dvec3(map_.texel(int(i % std::size_t(map_.width)), int(i / std::size_t(map_.width))));
  for (DominantLight& light : lights_) {
    light.power = glm::dvec3(0.0);
    for (int k : light.texels) light.power += bright_[std::size_t(k)].radiance * bright_[std::size_t(k)].solid_angle;
  }
  set_fallback();
}

RoomRadiance::~RoomRadiance() = default;

// Fallback: the mean radiance of everything that is not bright.
void RoomRadiance::set_fallback() {
  const int W = map_.width, H = map_.height;
  glm::dvec3 dim_sum(0.0);
  double dim_omega = 0.0;
  for (int r = 0; r < H; ++r) {
    const double w = latlong_pixel_solid_angle(r, W, H);
    for (int c = 0; c < W; ++c)
      if (!is_bright(c, r)) {
        dim_sum += glm::dvec3(map_.texel(c, r)) * w;
        dim_omega += w;
      }
  }
  fallback_ = dim_omega > 0.0 ? dim_sum / dim_omega : glm::dvec3(0.0);
}

void RoomRadiance::prepare(const EnvironmentMap& loaded) {
  if (loaded.width <= 0 || loaded.height <= 0 || loaded.rgb.size() != std::size_t(loaded.width) * loaded.height * 3)
    throw InputError("room radiance: the environment map is empty; load it again");
  map_ = downsample_environment_map(loaded, settings_.map_height);
  const int W = map_.width, H = map_.height;
  const std::size_t n = std::size_t(W) * H;

  // Bright texels: brightest first, while they cover at most bright_fraction of the sphere.
  std::vector<double> lum(n), omega(n);
  double lum_sum = 0.0;
  for (int r = 0; r < H; ++r) {
    const double w = latlong_pixel_solid_angle(r, W, H);
    for (int c = 0; c < W; ++c) {
      const std::size_t i = std::size_t(r) * W + c;
      lum[i] = luminance(glm::dvec3(map_.texel(c, r)));
      omega[i] = w;
      lum_sum += lum[i] * w;
    }
  }
  const double mean_lum = lum_sum / (4.0 * kPi);
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return lum[a] > lum[b]; });
  bright_index_.assign(n, -1);
  bright_.clear();
  lights_.clear();
  double covered = 0.0;
  const double budget = settings_.bright_fraction * 4.0 * kPi;
  threshold_ = std::numeric_limits<double>::infinity();
  for (std::size_t i : order) {
    if (lum[i] < settings_.bright_min_ratio * mean_lum || lum[i] <= 0.0 || covered + omega[i] > budget) {
      threshold_ = lum[i];
      break;
    }
    covered += omega[i];
    const int c = int(i % W), r = int(i / W);
    BrightTexel t;
    t.radiance = glm::dvec3(map_.texel(c, r));
    t.solid_angle = omega[i];
    t.direction = glm::normalize(map_.world_direction(latlong_pixel_direction(c, r, W, H)));
    place_on_proxy(rays_.get(), map_.capture_position, t);
    bright_index_[i] = int(bright_.size());
    bright_.push_back(t);
  }

  set_fallback();

  // Dominant lights: 8-connected clusters of bright texels (wrapping in azimuth). A
  // cluster too large to be one light (a bright sky around the sun) is split by raising
  // its threshold fourfold, until its parts are small enough.
  const auto components = [&](const std::vector<std::size_t>& texels) {
    std::vector<char> in(n, 0), seen(n, 0);
    for (std::size_t i : texels) in[i] = 1;
    std::vector<std::vector<std::size_t>> out;
    for (std::size_t seed : texels) {
      if (seen[seed]) continue;
      std::vector<std::size_t> comp, stack{seed};
      seen[seed] = 1;
      while (!stack.empty()) {
        const std::size_t i = stack.back();
        stack.pop_back();
        comp.push_back(i);
        const int c = int(i % W), r = int(i / W);
        for (int dr = -1; dr <= 1; ++dr)
          for (int dc = -1; dc <= 1; ++dc) {
            const int rr = r + dr;
            if (rr < 0 || rr >= H) continue;
            const std::size_t j = std::size_t(rr) * W + std::size_t(((c + dc) % W + W) % W);
            if (in[j] && !seen[j]) seen[j] = 1, stack.push_back(j);
          }
      }
      out.push_back(std::move(comp));
    }
    return out;
  };
  std::vector<std::size_t> all_bright;
  for (std::size_t i = 0; i < n; ++i)
    if (bright_index_[i] >= 0) all_bright.push_back(i);
  std::vector<DominantLight> clusters;
  std::vector<std::pair<std::vector<std::size_t>, int>> queue;
  for (auto& comp : components(all_bright)) queue.emplace_back(std::move(comp), 0);
  while (!queue.empty()) {
    auto [comp, depth] = std::move(queue.back());
    queue.pop_back();
    double omega_sum = 0.0, min_lum = std::numeric_limits<double>::infinity();
    for (std::size_t i : comp) omega_sum += omega[i], min_lum = std::min(min_lum, lum[i]);
    if (omega_sum > settings_.max_light_solid_angle) {
      if (depth >= 8) continue;
      std::vector<std::size_t> brighter;
      for (std::size_t i : comp)
        if (lum[i] >= 4.0 * min_lum) brighter.push_back(i);
      if (brighter.empty()) {
        // An evenly bright opening (a room's window, a courtyard's sky): tiles of about
        // the largest light's solid angle, so each gets its own sharp shadow. A shadow
        // interpolated between probes would blur the opening's penumbra over a cell; an
        // opening left to a distant map's SH9 would shadow an object only by its open
        // share, alike from every side.
        const double texels_per_tile = double(comp.size()) * settings_.max_light_solid_angle / omega_sum;
        const int side = std::max(1, int(std::floor(std::sqrt(texels_per_tile))));
        std::map<std::pair<int, int>, std::vector<std::size_t>> tiles;
        for (std::size_t i : comp) tiles[{int(i % W) / side, int(i / W) / side}].push_back(i);
        for (auto& [key, tile] : tiles) queue.emplace_back(std::move(tile), depth + 1);
        continue;
      }
      for (auto& sub : components(brighter)) queue.emplace_back(std::move(sub), depth + 1);
      continue;
    }
    DominantLight light;
    glm::dvec3 dir_sum(0.0);
    for (std::size_t i : comp) {
      const int k = bright_index_[i];
      light.texels.push_back(k);
      const BrightTexel& t = bright_[std::size_t(k)];
      light.power += t.radiance * t.solid_angle;
      light.solid_angle += t.solid_angle;
      dir_sum += t.direction * luminance(t.radiance) * t.solid_angle;
    }
    light.direction =
        glm::length(dir_sum) > 0.0 ? glm::normalize(dir_sum) : bright_[std::size_t(light.texels[0])].direction;
    clusters.push_back(std::move(light));
  }
  std::vector<int> candidates;
  for (int k = 0; k < int(clusters.size()); ++k)
    if (clusters[std::size_t(k)].solid_angle <= settings_.max_light_solid_angle) candidates.push_back(k);
  std::sort(candidates.begin(), candidates.end(), [&](int a, int b) {
    return luminance(clusters[std::size_t(a)].power) > luminance(clusters[std::size_t(b)].power);
  });
  if (int(candidates.size()) > settings_.max_lights) candidates.resize(std::size_t(std::max(0, settings_.max_lights)));
  for (int k : candidates) {
    DominantLight light = std::move(clusters[std::size_t(k)]);
    place_on_proxy(rays_.get(), map_.capture_position, light);
    for (int t : light.texels) bright_[std::size_t(t)].light = int(lights_.size());
    lights_.push_back(std::move(light));
  }
}

RoomRadiance::Sample RoomRadiance::lookup(const glm::dvec3& p, const glm::dvec3& w, bool dim) const {
  traced_rays_.fetch_add(1, std::memory_order_relaxed);
  Sample s;
  glm::dvec3 map_dir = w;
  if (rays_) {
    Ray ray;
    ray.origin = glm::vec3(p);
    ray.direction = glm::vec3(w);
    if (const auto hit = rays_->intersect(ray)) {
      s.distance = hit->t;
      const glm::dvec3 x = p + w * double(hit->t);
      s.back_face = hit->back_face;
      map_dir = x - map_.capture_position;
      const double len = glm::length(map_dir);
      if (len > 1e-6) {
        Ray back;
        back.origin = glm::vec3(map_.capture_position);
        back.direction = glm::vec3(map_dir);
        back.t_far = float(1.0 - 2e-3 / len);  // stop 2 mm before x
        if (rays_->occluded(back)) {
          fallback_rays_.fetch_add(1, std::memory_order_relaxed);
          s.fallback = true;
          s.radiance = fallback_;
          return s;
        }
      }
    }
  }
  const glm::dvec2 uv = latlong_coordinates(map_.map_direction(map_dir), map_.width, map_.height);
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return s;
  const int col = std::clamp(int(uv.x), 0, map_.width - 1), row = std::clamp(int(uv.y), 0, map_.height - 1);
  if (dim && is_bright(col, row)) return s;
  s.radiance = glm::dvec3(map_.texel(col, row));
  return s;
}

RoomRadiance::Sample RoomRadiance::dim_radiance(const glm::dvec3& p, const glm::dvec3& w) const {
  return lookup(p, w, true);
}
RoomRadiance::Sample RoomRadiance::radiance(const glm::dvec3& p, const glm::dvec3& w) const {
  return lookup(p, w, false);
}

double patch_area(const glm::dvec3& capture, const glm::dvec3& position, const glm::dvec3& normal, double solid_angle) {
  const glm::dvec3 vc = capture - position;
  const double rc2 = glm::dot(vc, vc);
  const double cos_c = std::max(glm::dot(normal, vc) / std::sqrt(rc2), 1e-3);
  return solid_angle * rc2 / cos_c;
}

double patch_solid_angle_from(const glm::dvec3& p, const glm::dvec3& capture, const glm::dvec3& position,
                              const glm::dvec3& normal, double solid_angle, glm::dvec3* toward) {
  const glm::dvec3 v = p - position;
  const double r2 = glm::dot(v, v);
  if (r2 < 1e-12) return 0.0;
  const double r = std::sqrt(r2);
  if (toward) *toward = -v / r;
  const double cos_p = glm::dot(normal, v) / r;
  if (cos_p <= 0.0) return 0.0;
  return std::min(patch_area(capture, position, normal, solid_angle) * cos_p / r2, 2.0 * kPi);
}

double RoomRadiance::solid_angle_from(const glm::dvec3& p, bool on_proxy, const glm::dvec3& position,
                                      const glm::dvec3& normal, const glm::dvec3& direction, double solid_angle,
                                      glm::dvec3* toward) const {
  if (!on_proxy) {
    if (toward) *toward = direction;
    return solid_angle;
  }
  return patch_solid_angle_from(p, map_.capture_position, position, normal, solid_angle, toward);
}

bool RoomRadiance::sees(const glm::dvec3& p, bool on_proxy, const glm::dvec3& position,
                        const glm::dvec3& direction) const {
  if (!rays_) return true;
  Ray ray;
  ray.origin = glm::vec3(p);
  if (on_proxy) {
    const glm::dvec3 d = position - p;
    const double len = glm::length(d);
    if (len < 1e-6) return true;
    ray.direction = glm::vec3(d);
    ray.t_far = float(1.0 - 2e-3 / len);
  } else {
    ray.direction = glm::vec3(direction);
  }
  return !rays_->occluded(ray);
}

}  // namespace lumar
