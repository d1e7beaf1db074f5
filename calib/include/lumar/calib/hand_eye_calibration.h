#pragma once
// Hand-eye calibration of a tracked camera: where the camera sits on the tracker's
// sensor (T_sensor_camera) and where the calibration board sits in the transmitter's
// frame (T_transmitter_board), from simultaneous tracker poses and board poses.
//
// cv::calibrateHandEye solves AX = XB with the sensor as the robot's "gripper" and the
// transmitter as its "base": gripper2base = T_transmitter_sensor, target2cam =
// T_camera_board, cam2gripper = T_sensor_camera.
#include <vector>

#include "lumar/base/pose.h"

namespace lumar::calib {

enum class HandEyeMethod { Tsai, Park, Horaud, Andreff, Daniilidis };

struct HandEyeOptions {
  HandEyeMethod method = HandEyeMethod::Park;
  // OpenCV pairs every selected view with every other; relative motions with a small
  // rotation carry mostly noise, so views are picked to be far apart in orientation
  // (farthest-point sampling over the sensor's rotations), at most this many.
  int max_views = 60;
};

struct HandEyeSolution {
  Pose T_sensor_camera;
  Pose T_transmitter_board;          // mean over the views of T_transmitter_sensor * X * T_camera_board
  std::vector<int> views_used;       // indices into the inputs given to cv::calibrateHandEye
  double min_pair_rotation_deg = 0;  // smallest rotation between two selected views
};

// T_transmitter_sensor[i] and T_camera_board[i] describe the same instant. Throws
// InputError when fewer than 3 views are given or the sizes differ.
HandEyeSolution solve_hand_eye(const std::vector<Pose>& T_transmitter_sensor, const std::vector<Pose>& T_camera_board,
                               const HandEyeOptions& options = {});

// Indices of up to `count` rotations spread out by farthest-point sampling (greedy,
// starting from the first): each pick maximises its smallest angle to those before it.
std::vector<int> spread_rotations(const std::vector<glm::dquat>& rotations, int count);

// Chordal L2 mean of rotations (the normalised sum of sign-aligned quaternions, which
// is the maximum-likelihood mean for small isotropic noise) and mean of translations.
Pose mean_pose(const std::vector<Pose>& poses);

}  // namespace lumar::calib
