#pragma once
// Lat-long environment map convention: W x H with W = 2H, row 0 at the top.
// Continuous map coordinates (u, v) run over [0, W] x [0, H]; the centre of pixel
// (c, r) is (c + 0.5, r + 0.5). phi = 2*pi*u/W, theta = pi*v/H (theta from +Y),
// d = (sin(theta) cos(phi), cos(theta), sin(theta) sin(phi)) in the map's frame.
#include <glm/glm.hpp>

namespace lumar {

// Direction of continuous map coordinates (u, v).
glm::dvec3 latlong_direction(double u, double v, int width, int height);
// Direction through the centre of pixel (col, row).
inline glm::dvec3 latlong_pixel_direction(int col, int row, int width, int height) {
  return latlong_direction(col + 0.5, row + 0.5, width, height);
}
// Continuous map coordinates of a direction (need not be unit); u in [0, W), v in [0, H].
glm::dvec2 latlong_coordinates(const glm::dvec3& direction, int width, int height);
// Solid angle of one pixel of row `row`, in steradians; the rows sum to 4*pi.
double latlong_pixel_solid_angle(int row, int width, int height);

}  // namespace lumar
