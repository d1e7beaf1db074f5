#pragma once
// A synthetic sweep kept in memory: the calibrated webcam turning about the capture
// point of a shared HDR map, 8-bit frames at several exposures, the true rotations and
// the rotations a tracker with 0.75 degrees RMS noise would report.
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/envmap/orientation_refinement.h"
#include "lumar/scene/envmap.h"
#include "lumar/sim/envmap_view.h"

namespace lumar::test {

struct SweepSpec {
  std::string map = "studio";  // a map in shared/data/envmaps
  int frames = 180;            // 60 stations of 3
  // Relative to 18 % grey; bracketed: the camera stands still for each bracket.
  std::vector<double> exposure_stops = {4.0, -1.0, -6.0};
  double tracker_noise_deg = 0.75;
  unsigned seed = 7;
};

struct Sweep {
  EnvironmentMap source;
  CameraIntrinsics camera;
  sim::SensorModel sensor;
  std::vector<cv::Mat> frames;      // CV_8UC3 BGR
  std::vector<double> exposures;    // video linear value per unit radiance
  std::vector<glm::dquat> truth;    // R_world_camera
  std::vector<glm::dquat> tracker;  // truth with tracker noise
  std::vector<int> groups;          // the bracket (station) of each frame
};

// Built once per spec and kept for the rest of the test run.
const Sweep& synthetic_sweep(const SweepSpec& spec);
// The sweep's tracker rotations refined from its frames (brackets grouped), also kept.
const calib::RefinementResult& refined_sweep(const SweepSpec& spec);

CameraIntrinsics webcam();
// Exposure that puts the map's mean luminance (solid-angle weighted) at 18 % grey.
double auto_exposure(const EnvironmentMap& map);
// RMS angle between two lists of rotations, degrees.
double rms_angle_deg(const std::vector<glm::dquat>& a, const std::vector<glm::dquat>& b);

}  // namespace lumar::test
