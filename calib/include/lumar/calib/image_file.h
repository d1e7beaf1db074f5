#pragma once
// Image files written whole or not at all (lumar/base/output_file.h), in the format
// their extension names (.png, .jpg, .hdr, ...).
#include <filesystem>
#include <opencv2/core.hpp>

namespace lumar::calib {

// InputError naming the file when OpenCV cannot encode the image in that format (an
// unknown extension); RuntimeError when it cannot be written.
void write_image_atomically(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace lumar::calib
