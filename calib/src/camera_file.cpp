#include "lumar/calib/camera_file.h"

#include <opencv2/core/persistence.hpp>

#include "lumar/base/error.h"
#include "lumar/base/output_file.h"

namespace lumar::calib {

CameraFile load_camera_file(const std::filesystem::path& path) {
  const std::string name = path.string();
  if (!std::filesystem::is_regular_file(path)) throw InputError(name + ": camera calibration file not found");
  cv::FileStorage fs;
  try {
    if (!fs.open(name, cv::FileStorage::READ | cv::FileStorage::FORMAT_YAML))
      throw InputError(name + ": cannot open as OpenCV YAML");
  } catch (const cv::Exception&) {
    throw InputError(name + ": not a valid OpenCV FileStorage YAML file");
  }
  CameraFile out;
  cv::Mat K, D;
  int w = 0, h = 0;
  try {
    fs["camera_matrix"] >> K;
    fs["distortion_coefficients"] >> D;
    fs["image_width"] >> w;
    fs["image_height"] >> h;
    if (!fs["avg_reprojection_error"].empty()) fs["avg_reprojection_error"] >> out.avg_reprojection_error;
  } catch (const cv::Exception&) {
    throw InputError(name + ": malformed calibration entries");
  }
  if (K.rows != 3 || K.cols != 3) throw InputError(name + ": camera_matrix is missing or not 3x3");
  if (D.total() != 4 && D.total() != 5)
    throw InputError(name + ": distortion_coefficients must hold 4 or 5 values (k1 k2 p1 p2 [k3])");
  K.convertTo(K, CV_64F);
  D.convertTo(D, CV_64F);
  CameraIntrinsics& c = out.intrinsics;
  c.width = w;
  c.height = h;
  c.fx = K.at<double>(0, 0);
  c.fy = K.at<double>(1, 1);
  c.cx = K.at<double>(0, 2);
  c.cy = K.at<double>(1, 2);
  for (size_t i = 0; i < D.total(); ++i) c.distortion[i] = D.at<double>(int(i));
  if (!c.is_valid()) throw InputError(name + ": image size or focal lengths are missing, non-positive or not finite");
  return out;
}

void save_camera_file(const std::filesystem::path& path, const CameraFile& camera) {
  // Into memory first, then onto disk whole (lumar/base/output_file.h).
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  fs << "image_width" << camera.intrinsics.width;
  fs << "image_height" << camera.intrinsics.height;
  fs << "camera_matrix" << cv::Mat(camera.intrinsics.camera_matrix());
  fs << "distortion_coefficients" << camera.intrinsics.distortion_coefficients();
  fs << "avg_reprojection_error" << camera.avg_reprojection_error;
  write_file_atomically(path, fs.releaseAndGetString());
}

}  // namespace lumar::calib
