#include "lumar/calib/camera_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <opencv2/core/persistence.hpp>

#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/base/output_file.h"

namespace lumar::calib {

namespace {

// The YAML a camera file may hold: "key: value" lines (a key alone before a nested map
// or list), nested by indentation, "- value" list items, "[ ... ]" sequences that may
// span lines; the "%YAML:1.0" and "---" lines; comments. OpenCV 4.6's parser loops forever on some text outside
// this ("a:]" followed by a line without a colon, found by fuzz_camera_yaml), so such
// text is refused before it gets there.
void check_yaml_lines(const std::string& text, const std::string& name) {
  int depth = 0;  // open '[' (and '{') across lines
  std::size_t number = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    std::string line = text.substr(at, end - at);
    at = end + 1;
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t first = line.find_first_not_of(' ');
    const auto bad = [&](const std::string& why) {
      throw InputError(name + ":" + std::to_string(number) + ": " + why +
                       "; not an OpenCV camera file (rewrite it as `lumar calibrate` writes them)");
    };
    const bool item = first != std::string::npos && line[first] == '-' &&
                      (first + 1 == line.size() || line[first + 1] == ' ');  // "- value" in a list
    if (depth == 0 && first != std::string::npos && line[first] != '#' && line[first] != '[' && !item &&
        !(number == 1 && line.rfind("%YAML", 0) == 0) && line != "---" && line != "...") {
      std::size_t k = first;
      while (k < line.size() && (std::isalnum(static_cast<unsigned char>(line[k])) || line[k] == '_')) ++k;
      if (k == first || k >= line.size() || line[k] != ':') bad("expected \"key: value\"");
      if (k + 1 < line.size() && line[k + 1] != ' ') bad("a key's ':' must be followed by a space");
    }
    for (char c : line) {
      if (c == '[' || c == '{') ++depth;
      if (c == ']' || c == '}') --depth;
      if (depth < 0) bad("a ']' closes nothing");
    }
  }
  if (depth != 0) throw InputError(name + ": a '[' is never closed; the file is cut short or damaged");
}

}  // namespace

CameraFile load_camera_file(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string text = read_input_file(path, "camera calibration file", 1 << 20);
  check_yaml_lines(text, name);
  cv::FileStorage fs;
  bool opened = false;
  try {
    opened = fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const std::exception&) {  // cv::Exception, and std::length_error on some damaged files
    throw InputError(name + ": not a valid OpenCV FileStorage YAML file");
  }
  if (!opened) throw InputError(name + ": cannot open as OpenCV YAML");
  CameraFile out;
  cv::Mat K, D;
  int w = 0, h = 0;
  try {
    // The declared sizes first: OpenCV allocates rows x cols before it reads the data, so
    // a damaged "cols" asked for 51 GB.
    const auto declared = [&](const char* key, int most) {
      const cv::FileNode node = fs[key];
      if (!node.isMap()) return;  // missing or not a matrix: said below
      const double rows = node["rows"].isInt() ? double(int(node["rows"])) : -1.0;
      const double cols = node["cols"].isInt() ? double(int(node["cols"])) : -1.0;
      if (rows < 1 || cols < 1 || rows * cols > most)
        throw InputError(name + ": " + key + " declares " + std::to_string(std::int64_t(rows)) + "x" +
                         std::to_string(std::int64_t(cols)) + " values (rows x cols); it holds at most " +
                         std::to_string(most));
    };
    declared("camera_matrix", 9);
    declared("distortion_coefficients", 5);
    fs["camera_matrix"] >> K;
    fs["distortion_coefficients"] >> D;
    fs["image_width"] >> w;
    fs["image_height"] >> h;
    if (!fs["avg_reprojection_error"].empty()) fs["avg_reprojection_error"] >> out.avg_reprojection_error;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception&) {
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
  if (!std::isfinite(out.avg_reprojection_error) || out.avg_reprojection_error < 0)
    throw InputError(name + ": avg_reprojection_error is negative or not finite");
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
