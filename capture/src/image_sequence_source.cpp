#include "lumar/capture/image_sequence_source.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <span>
#include <utility>

#include "lumar/base/csv.h"
#include "lumar/base/error.h"
#include "lumar/base/glob.h"
#include "lumar/base/input_file.h"

namespace lumar::capture {
namespace fs = std::filesystem;

namespace {

bool is_image(const fs::path& p) {
  static const std::set<std::string> kExtensions{".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm"};
  return kExtensions.count(lower_case_extension(p)) > 0;
}

std::vector<fs::path> expand(const std::string& pattern) {
  std::vector<fs::path> out;
  std::error_code ec;
  if (fs::is_directory(pattern, ec)) {
    for (const auto& e : fs::directory_iterator(pattern, ec))
      if (e.is_regular_file() && is_image(e.path())) out.push_back(e.path());
  } else {
    return glob_files(pattern);
  }
  std::sort(out.begin(), out.end(),
            [](const fs::path& a, const fs::path& b) { return natural_less(a.string(), b.string()); });
  return out;
}

// The folder the images live in: the pattern itself, or the folder part of a glob.
fs::path image_folder(const std::string& pattern) {
  std::error_code ec;
  if (fs::is_directory(pattern, ec)) return pattern;
  return fs::path(pattern).parent_path();
}

}  // namespace

ImageSequenceSource::ImageSequenceSource(ImageSequenceSettings settings) : settings_(std::move(settings)) {
  const std::string& pattern = settings_.pattern;
  if (pattern.empty())
    throw InputError("images: no folder or glob given; use e.g. images:shots/ or 'images:shots/*.png'");
  if (settings_.timestamps.empty()) {
    if (!(settings_.fps > 0) || !std::isfinite(settings_.fps))
      throw InputError(pattern + ": an image sequence needs a timestamp table or a frame rate (--fps)");
    files_ = expand(pattern);
    if (files_.empty())
      throw InputError(pattern + ": no image files (png, jpg, bmp, tif, ppm) found; check the folder or glob");
    for (std::size_t i = 0; i < files_.size(); ++i)
      times_.push_back(Nanos(std::llround(double(i) * 1e9 / settings_.fps)));
    fps_ = settings_.fps;
  } else {
    const fs::path& table = settings_.timestamps;
    const fs::path folder = image_folder(pattern);
    csv::for_each_row(table, read_input_file(table, "timestamp table"), {{"file", "time_ns"}},
                      csv::LastLine::kIgnoreTorn, [&](const csv::Row& row) {
                        const Nanos t = row.integer("time_ns");
                        if (!times_.empty() && t <= times_.back())
                          row.fail("time " + std::to_string(t) + " does not increase; the rows must be in time order");
                        const fs::path file = folder / std::string(row.text("file"));
                        if (auto problem = input_file_problem(file))
                          row.fail("image " + file.string() + " " + *problem);
                        files_.push_back(file);
                        times_.push_back(t);
                      });
    if (files_.empty()) throw InputError(table.string() + ": the timestamp table lists no frames");
    if (times_.size() > 1) fps_ = double(times_.size() - 1) / nanos_to_seconds(times_.back() - times_.front());
  }
  first_ = decode(0, &first_chroma_);
  size_ = first_.size();
}

cv::Mat ImageSequenceSource::decode(std::size_t i, ChromaSampling* chroma) const {
  // Read once: the decoder and, for a JPEG, its frame header's chroma sampling.
  const std::string bytes = read_input_file(files_[i], "image");
  const std::span<const std::uint8_t> data(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  cv::Mat img;
  if (!bytes.empty())  // BGR8, whatever the file holds
    img = cv::imdecode(cv::Mat(1, int(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data())), cv::IMREAD_COLOR);
  if (img.empty()) throw InputError(files_[i].string() + ": cannot decode this image; it is corrupt or not an image");
  // Other formats hold no chroma samples of their own (PNG, BMP, TIFF and PPM store RGB).
  if (chroma) *chroma = chroma_sampling_of_jpeg(data);
  return img;
}

bool ImageSequenceSource::read(Frame& frame) {
  if (next_ >= files_.size()) return false;
  const std::size_t i = next_++;  // a bad file is reported once, then skipped
  ChromaSampling chroma = first_chroma_;
  cv::Mat img = i == 0 ? std::exchange(first_, cv::Mat()) : decode(i, &chroma);
  if (img.size() != size_)
    throw InputError(files_[i].string() + ": is " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                     ", the sequence started at " + std::to_string(size_.width) + "x" + std::to_string(size_.height) +
                     "; every image must have the same size");
  frame.image = img;
  frame.time = times_[i];
  frame.index = std::int64_t(i);
  frame.chroma = chroma;
  return true;
}

}  // namespace lumar::capture
