#pragma once
// HDR lat-long environment maps (convention in latlong.h). A map knows where it was
// captured (a world point) and its azimuth offset: world direction = Ry(offset) * map
// direction, a rotation about +Y by azimuth_offset_deg.
#include <filesystem>
#include <glm/glm.hpp>
#include <vector>

namespace lumar {

struct EnvironmentMap {
  int width = 0, height = 0;
  std::vector<float> rgb;  // row-major from the top row, 3 linear floats per pixel
  glm::dvec3 capture_position{0.0};
  double azimuth_offset_deg = 0.0;

  glm::vec3 texel(int col, int row) const {
    const float* p = &rgb[(std::size_t(row) * width + col) * 3];
    return {p[0], p[1], p[2]};
  }
  glm::dvec3 map_direction(const glm::dvec3& world_direction) const;
  glm::dvec3 world_direction(const glm::dvec3& map_direction) const;
  // Radiance arriving from a world direction: bilinear, wrapping around in azimuth.
  glm::vec3 radiance(const glm::dvec3& world_direction) const;
};

// Mean luminance over the sphere, each texel weighted by its solid angle.
double mean_luminance(const EnvironmentMap& map);

// A coarse grid of RGB factors over a map's own lat-long directions (row 0 at the top):
// how each part of the room's light changed (pipeline/live_lighting.h). One cell of 1: none.
struct MapCellScale {
  int cols = 1, rows = 1;
  std::vector<glm::vec3> rgb{glm::vec3(1.0f)};  // rows x cols, row-major

  // The factor of the cell a map direction (need not be unit) falls in.
  glm::vec3 at(const glm::dvec3& map_direction) const;
  // (1 - w) a + w b, cell by cell; the grids must match.
  static MapCellScale blend(const MapCellScale& a, const MapCellScale& b, double w);
};

// The map relit: each texel times the factor of the cell its centre falls in.
// InputError when the grid and its factors disagree.
EnvironmentMap scale_environment_map(const EnvironmentMap& map, const MapCellScale& scale);

// Reads an OpenEXR or Radiance HDR file through OpenImageIO (first three channels).
// Throws InputError naming the file when it is missing, unreadable or not 2:1.
EnvironmentMap load_environment_map(const std::filesystem::path& path);
// Writes float OpenEXR, atomically.
void save_environment_map(const std::filesystem::path& path, const EnvironmentMap& map);

}  // namespace lumar
