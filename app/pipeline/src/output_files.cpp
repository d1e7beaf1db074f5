#include "lumar/pipeline/output_files.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"
#include "lumar/calib/image_file.h"

namespace lumar::pipeline {

namespace fs = std::filesystem;

namespace {
fs::path checked_video_path(fs::path path) {
  if (path.extension() != ".mp4" && path.extension() != ".mkv" && path.extension() != ".avi")
    throw InputError(path.string() + ": output video must end in .mp4, .mkv or .avi");
  return path;
}
}  // namespace

VideoOutput::VideoOutput(fs::path path, double fps, cv::Size size) : file_(checked_video_path(std::move(path))) {
  // The encoder says only that it failed; creating the file first says why (a read-only
  // folder, no permission).
  if (std::FILE* probe = std::fopen(file_.temporary().c_str(), "wb"))
    std::fclose(probe);
  else
    throw RuntimeError(file_.path().string() + ": cannot create the video: " + std::strerror(errno));
  // H.264 where the FFmpeg build has an encoder for it, else MPEG-4 part 2. The
  // temporary keeps the extension, so FFmpeg picks the same container.
  for (const char* fourcc : {"avc1", "mp4v"}) {
    writer_.open(file_.temporary().string(), cv::CAP_FFMPEG,
                 cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]), fps, size);
    if (writer_.isOpened()) {
      codec_ = fourcc;
      return;
    }
  }
  throw RuntimeError(file_.path().string() + ": no video encoder available (tried H.264 and MPEG-4)");
}

VideoOutput::~VideoOutput() { writer_.release(); }

void VideoOutput::write(const cv::Mat& bgr8) {
  writer_.write(bgr8);
  ++frames_;
}

void VideoOutput::commit() {
  writer_.release();
  // OpenCV's writer reports no write error: a full disk leaves a cut file that no player
  // opens. So the video is read back before it takes its final name.
  if (frames_ > 0) {
    cv::VideoCapture check(file_.temporary().string(), cv::CAP_FFMPEG);
    const auto held = check.isOpened() ? std::int64_t(check.get(cv::CAP_PROP_FRAME_COUNT)) : 0;
    if (held < frames_)
      throw RuntimeError(
          fmt::format("{}: the video could not be written whole (is the disk full?): it holds {} of {} "
                      "frames",
                      file_.path().string(), held, frames_));
  }
  file_.commit();
}

FramesOutput::FramesOutput(fs::path dir) : folder_(std::move(dir)) {}

void FramesOutput::write(std::int64_t index, const cv::Mat& bgr8) {
  const fs::path file = folder_.temporary() / fmt::format("frame-{:06d}.png", index);
  // Encoded in memory and written here, so that a failed write (a full disk) is one
  // error of ours with its reason, not libpng's message on stderr besides.
  std::vector<uchar> png;
  if (!cv::imencode(".png", bgr8, png)) throw RuntimeError("cannot encode frame " + std::to_string(index) + " as PNG");
  std::FILE* out = std::fopen(file.c_str(), "wb");
  int error = out ? 0 : errno;
  if (out && std::fwrite(png.data(), 1, png.size(), out) != png.size()) error = errno;
  if (out && std::fclose(out) != 0 && error == 0) error = errno;  // buffered bytes fail here
  if (error != 0)
    throw RuntimeError((folder_.path() / file.filename()).string() + ": cannot write PNG: " + std::strerror(error));
}

void FramesOutput::commit() { folder_.commit(); }

void write_contact_sheet(const fs::path& png, const std::vector<std::pair<std::int64_t, cv::Mat>>& frames, int columns,
                         int tile_width) {
  if (frames.empty()) return;
  const cv::Size first = frames.front().second.size();
  const cv::Size tile(tile_width, tile_width * first.height / first.width);
  const int rows = (int(frames.size()) + columns - 1) / columns;
  cv::Mat sheet(rows * tile.height, std::min<int>(columns, frames.size()) * tile.width, CV_8UC3, cv::Scalar::all(0));
  for (std::size_t i = 0; i < frames.size(); ++i) {
    cv::Mat cell =
        sheet(cv::Rect(int(i % columns) * tile.width, int(i / columns) * tile.height, tile.width, tile.height));
    cv::resize(frames[i].second, cell, tile, 0, 0, cv::INTER_AREA);
    const std::string label = fmt::format("frame {}", frames[i].first);
    cv::putText(cell, label, {7, 19}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar::all(0), 2, cv::LINE_AA);
    cv::putText(cell, label, {7, 19}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar::all(255), 1, cv::LINE_AA);
  }
  calib::write_image_atomically(png, sheet);
}

OverlayOutputs::OverlayOutputs(const OverlayOutputSettings& s) : settings_(s) {
  if (!s.contact_sheet.empty() && fs::path(s.contact_sheet).extension() != ".png")
    throw InputError(s.contact_sheet + ": the contact sheet must be a .png file");
  if (!s.video.empty()) video_.emplace(s.video, s.fps, s.size);
  if (!s.frames_dir.empty()) frames_.emplace(s.frames_dir);
}

void OverlayOutputs::write(std::int64_t index, const cv::Mat& bgr8) {
  // Eight frames spread evenly over the run, for the contact sheet.
  const std::int64_t total = settings_.expected_frames;
  if (!settings_.contact_sheet.empty() && sheet_.size() < 8 && seen_ * 7 >= std::int64_t(sheet_.size()) * (total - 1))
    sheet_.emplace_back(index, bgr8.clone());
  ++seen_;
  if (video_) video_->write(bgr8);
  if (frames_) frames_->write(index, bgr8);
}

void OverlayOutputs::commit() {
  if (video_) video_->commit();
  if (frames_) frames_->commit();
  if (!settings_.contact_sheet.empty()) write_contact_sheet(settings_.contact_sheet, sheet_);
}

std::string OverlayOutputs::describe() const {
  return video_ ? " -> " + settings_.video + " (" + video_->codec() + ")" : std::string();
}

}  // namespace lumar::pipeline
