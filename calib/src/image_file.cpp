#include "lumar/calib/image_file.h"

#include <opencv2/imgcodecs.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "lumar/base/error.h"
#include "lumar/base/output_file.h"

namespace lumar::calib {

void write_image_atomically(const std::filesystem::path& path, const cv::Mat& image) {
  const std::string ext = path.extension().string();
  std::vector<uchar> bytes;
  bool encoded = false;
  try {
    encoded = !ext.empty() && cv::imencode(ext, image, bytes);
  } catch (const cv::Exception&) {
    encoded = false;
  }
  if (!encoded)
    throw InputError(path.string() + ": cannot write an image in the format '" + ext + "'; use .png, .jpg or .hdr");
  write_file_atomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace lumar::calib
