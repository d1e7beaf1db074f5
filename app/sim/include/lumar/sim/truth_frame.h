#pragma once
// The frame a camera would have seen with the scene's objects physically in the room
// (docs/ground_truth.md): from the empty room's radiance image at the same pose, each
// pixel's ray meets either an object (its radiance from lighting/composite_reference.h)
// or the room (the empty room's radiance × (E_with + E_bounce) / E_without there).
#include <opencv2/core.hpp>

#include "lumar/base/camera.h"
#include "lumar/base/pose.h"
#include "lumar/lighting/composite_reference.h"
#include "lumar/lighting/ray_scene.h"

namespace lumar::sim {

struct TruthSettings {
  // The room's ratio is sampled every `ratio_stride` pixels and interpolated between
  // (it is smooth but for contact shadows; 1 = every pixel).
  int ratio_stride = 4;
  // Each object pixel integrates its own E; false: its vertices' E, interpolated (a
  // fraction of the cost, but 5.6 % off on the figurine, against 2.3 % of ray noise).
  bool per_pixel_objects = true;
};

struct TruthFrame {
  cv::Mat radiance;  // CV_32FC3 BGR, scene units, the empty room's size
  cv::Mat coverage;  // CV_32FC1: 1 where an object is seen, else 0
};

// `empty_radiance`: the room without objects as `camera` (a pinhole) sees it from
// T_world_camera (CV_32FC3 BGR). Pixel (c, r) looks along the ray through (c, r) in
// OpenCV's convention (docs/conventions.md). `room_surfaces`: the room the empty image
// shows, where the objects' shadows fall: the proxy (RoomRadiance::ray_scene()), or the
// room's mesh under a distant map (the ground it is shown on), which that map's
// RoomRadiance does not hold.
TruthFrame render_truth_frame(const CompositeReference& reference, const RayScene& room_surfaces,
                              const CameraIntrinsics& camera, const Pose& T_world_camera, const cv::Mat& empty_radiance,
                              const TruthSettings& settings = {});

}  // namespace lumar::sim
