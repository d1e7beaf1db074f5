#include "lumar/scene/envmap.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include "decode_counter.h"
#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/base/latlong.h"
#include "lumar/base/output_file.h"

namespace lumar {

namespace {

// Rotation about +Y, right-handed: Ry(a) maps +Z to (sin a, 0, cos a).
glm::dvec3 rotate_y(const glm::dvec3& d, double angle_deg) {
  const double a = glm::radians(angle_deg), c = std::cos(a), s = std::sin(a);
  return {c * d.x + s * d.z, d.y, -s * d.x + c * d.z};
}

}  // namespace

glm::dvec3 EnvironmentMap::map_direction(const glm::dvec3& world) const { return rotate_y(world, -azimuth_offset_deg); }

glm::dvec3 EnvironmentMap::world_direction(const glm::dvec3& map) const { return rotate_y(map, azimuth_offset_deg); }

glm::vec3 EnvironmentMap::radiance(const glm::dvec3& world) const {
  const glm::dvec2 uv = latlong_coordinates(map_direction(world), width, height);
  // A zero or non-finite direction has no texel; never index with NaN.
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return glm::vec3(0.f);
  // Texel centres sit at +0.5; shift so that integer coordinates are texel centres.
  const double x = uv.x - 0.5, y = uv.y - 0.5;
  const double x0 = std::floor(x), y0 = std::floor(y);
  const double fx = x - x0, fy = y - y0;
  const auto wrap = [&](long c) { return int(((c % width) + width) % width); };
  const auto clamp_row = [&](long r) { return int(std::clamp<long>(r, 0, height - 1)); };
  const int c0 = wrap(long(x0)), c1 = wrap(long(x0) + 1);
  const int r0 = clamp_row(long(y0)), r1 = clamp_row(long(y0) + 1);
  const glm::dvec3 top = glm::dvec3(texel(c0, r0)) * (1.0 - fx) + glm::dvec3(texel(c1, r0)) * fx;
  const glm::dvec3 bottom = glm::dvec3(texel(c0, r1)) * (1.0 - fx) + glm::dvec3(texel(c1, r1)) * fx;
  return glm::vec3(top * (1.0 - fy) + bottom * fy);
}

glm::vec3 MapCellScale::at(const glm::dvec3& map_direction) const {
  const glm::dvec2 uv = latlong_coordinates(glm::normalize(map_direction), cols, rows);
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return glm::vec3(1.0f);
  return rgb[std::size_t(std::clamp(int(uv.y), 0, rows - 1)) * std::size_t(cols) +
             std::size_t(std::clamp(int(uv.x), 0, cols - 1))];
}

MapCellScale MapCellScale::blend(const MapCellScale& a, const MapCellScale& b, double w) {
  if (a.cols != b.cols || a.rows != b.rows || a.rgb.size() != b.rgb.size())
    throw RuntimeError("MapCellScale::blend: grids of different sizes");
  MapCellScale out = b;
  for (std::size_t k = 0; k < out.rgb.size(); ++k) out.rgb[k] = float(1.0 - w) * a.rgb[k] + float(w) * b.rgb[k];
  return out;
}

EnvironmentMap scale_environment_map(const EnvironmentMap& map, const MapCellScale& scale) {
  const int cols = scale.cols, rows = scale.rows;
  if (cols < 1 || rows < 1 || scale.rgb.size() != std::size_t(cols) * std::size_t(rows))
    throw InputError("environment map: " + std::to_string(scale.rgb.size()) + " cell factors for a " +
                     std::to_string(cols) + "x" + std::to_string(rows) + " grid");
  EnvironmentMap out = map;
  for (int r = 0; r < map.height; ++r) {
    const int cell_row = std::min(rows - 1, int((r + 0.5) * rows / map.height));
    for (int c = 0; c < map.width; ++c) {
      const int cell_col = std::min(cols - 1, int((c + 0.5) * cols / map.width));
      const glm::vec3& k = scale.rgb[std::size_t(cell_row) * cols + std::size_t(cell_col)];
      float* p = &out.rgb[(std::size_t(r) * map.width + c) * 3];
      p[0] *= k.r, p[1] *= k.g, p[2] *= k.b;
    }
  }
  return out;
}

double mean_luminance(const EnvironmentMap& map) {
  double sum = 0, wsum = 0;
  for (int r = 0; r < map.height; ++r) {
    const double w = latlong_pixel_solid_angle(r, map.width, map.height);
    for (int c = 0; c < map.width; ++c) {
      sum += w * luminance(map.texel(c, r));
      wsum += w;
    }
  }
  return wsum > 0 ? sum / wsum : 0.0;
}

EnvironmentMap load_environment_map(const std::filesystem::path& path) {
  const std::string name = path.string();
  check_input_file(path, "environment map");
  auto in = OIIO::ImageInput::open(name);
  if (!in) {
    std::string why = OIIO::geterror();
    std::replace(why.begin(), why.end(), '\n', ' ');
    throw InputError(name + ": cannot read environment map (" + why +
                     "); give an OpenEXR or Radiance HDR lat-long image");
  }
  const OIIO::ImageSpec& spec = in->spec();
  const std::string format = in->format_name();
  // The name's extension picks the reader only as a first guess: a PNG named .exr opens,
  // and its 8-bit values would be taken for radiance.
  const std::string extension = lower_case_extension(path);
  const bool named_hdr = extension == ".exr" || extension == ".hdr";
  if ((named_hdr && format != "openexr" && format != "hdr") ||
      !(spec.format == OIIO::TypeDesc::HALF || spec.format == OIIO::TypeDesc::FLOAT ||
        spec.format == OIIO::TypeDesc::DOUBLE || format == "hdr"))
    throw InputError(name + ": environment map is a " + format + " image of " + std::string(spec.format.c_str()) +
                     " pixels, not high dynamic range; give an OpenEXR or Radiance HDR lat-long image");
  const int w = spec.width, h = spec.height, channels = spec.nchannels;
  if (w <= 0 || h <= 0 || channels <= 0) throw InputError(name + ": environment map has no pixels");
  if (w != 2 * h)
    throw InputError(name + ": environment map is " + std::to_string(w) + "x" + std::to_string(h) +
                     ", but a lat-long map must be twice as wide as high; resample it to 2:1");

  EnvironmentMap map;
  map.width = w;
  map.height = h;
  map.rgb.resize(std::size_t(w) * h * 3);
  // Colour maps give their first three channels; grey maps (1 or 2 channels) give
  // channel 0, replicated into R, G and B below.
  const int read_channels = channels >= 3 ? 3 : 1;
  std::vector<float> pixels(std::size_t(w) * h * read_channels);
  if (!in->read_image(0, 0, 0, read_channels, OIIO::TypeDesc::FLOAT, pixels.data())) {
    std::string why = in->geterror();
    std::replace(why.begin(), why.end(), '\n', ' ');
    throw InputError(name + ": cannot read environment map pixels (" + why + "); the file may be truncated or corrupt");
  }
  in->close();
  for (std::size_t i = 0, n = std::size_t(w) * h; i < n; ++i)
    for (int k = 0; k < 3; ++k) map.rgb[i * 3 + k] = pixels[i * read_channels + (read_channels == 3 ? k : 0)];

  const auto bad = std::find_if(map.rgb.begin(), map.rgb.end(), [](float v) { return !std::isfinite(v); });
  if (bad != map.rgb.end()) {
    const std::size_t pixel = std::size_t(bad - map.rgb.begin()) / 3;
    throw InputError(name + ": environment map pixel (" + std::to_string(pixel % w) + ", " + std::to_string(pixel / w) +
                     ") is not finite; repair the map");
  }
  // Radiance is never negative. A resampling filter's ringing leaves a few small negative
  // values (the shared maps hold some, down to -0.003, a millionth of their energy); those
  // are kept as the file has them. A map whose negative values weigh more is refused: it
  // would give negative irradiance.
  double negative = 0, positive = 0;
  float lowest = 0.f;
  for (float v : map.rgb) {
    (v < 0.f ? negative : positive) += std::abs(double(v));
    lowest = std::min(lowest, v);
  }
  if (negative > 1e-3 * positive)
    throw InputError(name + ": environment map holds negative radiance (lowest value " + std::to_string(lowest) + ", " +
                     std::to_string(int(std::round(100.0 * negative / std::max(positive, 1e-30)))) +
                     " % of the positive total); radiance cannot be negative: repair the map");
  count_decode(path);
  return map;
}

void save_environment_map(const std::filesystem::path& path, const EnvironmentMap& map) {
  const std::string name = path.string();
  if (map.width <= 0 || map.height <= 0 || map.rgb.size() != std::size_t(map.width) * map.height * 3)
    throw RuntimeError(name + ": cannot save an environment map whose pixel buffer does not match its size");
  OutputFile file(path);
  // Always OpenEXR, whatever the name ends in.
  auto out = OIIO::ImageOutput::create("openexr");
  if (!out) throw RuntimeError(name + ": OpenImageIO has no OpenEXR writer (" + OIIO::geterror() + ")");
  OIIO::ImageSpec spec(map.width, map.height, 3, OIIO::TypeDesc::FLOAT);
  spec.attribute("compression", "zip");
  const bool ok = out->open(file.temporary().string(), spec) &&
                  out->write_image(OIIO::TypeDesc::FLOAT, map.rgb.data()) && out->close();
  if (!ok) {
    std::string why = out->geterror();
    std::replace(why.begin(), why.end(), '\n', ' ');
    throw RuntimeError(name + ": cannot write environment map (" + why + "); check the folder and free space");
  }
  file.commit();
}

}  // namespace lumar
