#pragma once
// Camera calibration files: OpenCV FileStorage YAML with OpenCV's sample key names
// (camera_matrix, distortion_coefficients, image_width, image_height,
// avg_reprojection_error). Extra statistics may sit beside them.
#include <filesystem>

#include "lumar/base/camera.h"

namespace lumar::calib {

struct CameraFile {
  CameraIntrinsics intrinsics;
  double avg_reprojection_error = 0.0;  // pixels RMS; 0 when unknown
};

// Throws InputError naming the file when it is missing, unreadable or incomplete.
CameraFile load_camera_file(const std::filesystem::path& path);
// Writes atomically (temporary file, then rename).
void save_camera_file(const std::filesystem::path& path, const CameraFile& camera);

}  // namespace lumar::calib
