#include "lumar/calib/board_views.h"

#include <opencv2/imgcodecs.hpp>

#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/base/stop_signal.h"

namespace lumar::calib {

std::vector<NamedImage> load_board_images(const std::vector<std::filesystem::path>& paths) {
  std::vector<NamedImage> images;
  for (const auto& path : paths) {
    const std::string name = path.string();
    throw_if_stopped("calibrate: while reading " + name);
    if (const auto problem = input_file_problem(path))
      throw InputError(name + ": image " + *problem + "; check the path or remove it from the list");
    cv::Mat grey = cv::imread(name, cv::IMREAD_GRAYSCALE);
    if (grey.empty())
      throw InputError(name + ": cannot read image (missing or not an image file); remove it from the list");
    images.push_back({name, std::move(grey)});
  }
  return images;
}

void require_board_views(const BoardViews& views, std::size_t images, const std::string& board_text) {
  if (views.corners.empty())
    throw InputError("calibration: no " + board_text + " found in any of the " + std::to_string(images) +
                     " images; check the board size");
  if (views.corners.size() < 3)
    throw InputError("calibration: the board was found in only " + std::to_string(views.corners.size()) +
                     " image(s); at least 3 views are needed, better 10 or more at varied angles");
}

}  // namespace lumar::calib
