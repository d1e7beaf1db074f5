#pragma once
// The one stitching pipeline behind `lumar envmap`, whatever the sweep came from (a
// recording, a folder of images with poses): frames + tracked rotations + exposures
// -> orientation refinement -> stitching -> hole filling -> the outputs. Also the
// pieces the live path shares (outputs, progress, comparison with a reference map).
#include <filesystem>
#include <functional>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "lumar/envmap/envmap_stitcher.h"
#include "lumar/scene/envmap.h"

namespace lumar::pipeline {

// What the user asked for, common to every input.
struct EnvmapOutputOptions {
  std::string out, coverage, preview, corrections, reference;
  int width = 1024;
  // Refuse a map whose frames saw less than this share of the sphere (hole filling
  // would invent the rest); warn below kWellCoveredSphere.
  double min_coverage = 0.25;
  bool no_refine = false;
  bool no_fill = false;
  std::optional<double> azimuth_offset_deg;
};

// Below this share of the sphere seen, a map is mostly invented: stitch_sweep warns.
inline constexpr double kWellCoveredSphere = 0.6;
// Share of the seen sphere that may stay near black before the sweep is warned.
inline constexpr double kNearBlackShareWarned = 0.05;

// Throws InputError unless the width is a positive even number up to 16384.
void check_map_width(int width);

// A sweep, ready to stitch. Frames are read on demand (twice with refinement), in order.
struct SweepInput {
  std::string name;                              // for messages: the recording or the image folder
  calib::StitchSettings stitch;                  // camera, response, vignetting, capture point, azimuth, width
  std::vector<glm::dquat> rotations;             // tracked R_world_camera per frame
  std::vector<double> exposures;                 // video linear value per unit radiance, per frame
  std::vector<int> groups;                       // frames taken standing still share a group (empty: none)
  std::vector<std::string> labels;               // per frame, the first columns of --corrections rows
  std::string label_header = "frame";            // their header
  std::vector<std::optional<glm::dquat>> truth;  // true rotations when known (synthetic), else empty
  double tracker_noise_deg = 0.75;               // the refinement's prior
  // Calls use(image, k) for k = 0, 1, ... n-1 (CV_8UC3 BGR, the camera's size); throws
  // InputError when a frame cannot be read.
  std::function<void(const std::function<void(const cv::Mat&, int)>& use)> read_frames;
  std::string default_reference;  // reference map to compare with when --reference is not given
};

// Warns when the exposures did not span the scene: regions that stayed near black in
// every frame (their noise biases them up), and sources every frame saw clipped, the
// shortest exposure too (calib/envmap/clipped_sources.h); names the exposure to add.
// `map` is the stitcher's current_map(), made once by the caller (it is not cheap).
void warn_about_exposure_range(const calib::EnvmapStitcher& stitcher, const EnvironmentMap& map,
                               const std::vector<double>& exposures);

// Refines, stitches, fills and writes every output asked for.
void stitch_sweep(const SweepInput& input, const EnvmapOutputOptions& options);

// Fills the map's holes (coverage count 0) when asked, writes the EXR and the coverage /
// preview PNGs (each atomically). Returns the fraction of the map's pixels covered;
// `filled` gets the number of filled pixels.
double write_envmap_outputs(EnvironmentMap map, const cv::Mat& coverage, const EnvmapOutputOptions& options,
                            int* filled = nullptr);

// Logs the median relative luminance error, on covered pixels, of `map` against the
// reference map (box-filtered to the map's size) when one is given and its width is a
// multiple of the map's; returns it (nullopt when not compared).
std::optional<double> compare_with_reference(const EnvironmentMap& map, const cv::Mat& coverage,
                                             const std::string& reference);

}  // namespace lumar::pipeline
