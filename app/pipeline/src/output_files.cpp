#include "lumar/pipeline/output_files.h"

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"

namespace lumar::app {

namespace fs = std::filesystem;

VideoOutput::VideoOutput(fs::path path, double fps, cv::Size size) : path_(std::move(path)) {
  if (path_.extension() != ".mp4" && path_.extension() != ".mkv" && path_.extension() != ".avi")
    throw InputError(path_.string() + ": output video must end in .mp4, .mkv or .avi");
  if (!path_.parent_path().empty() && !fs::is_directory(path_.parent_path()))
    throw InputError(path_.string() + ": folder " + path_.parent_path().string() + " does not exist");
  // The partial file keeps the extension so that FFmpeg picks the same container.
  partial_ = path_.parent_path() / fmt::format(".{}.partial{}", path_.stem().string(), path_.extension().string());
  // H.264 where the FFmpeg build has an encoder for it, else MPEG-4 part 2.
  for (const char* fourcc : {"avc1", "mp4v"}) {
    writer_.open(partial_.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]),
                 fps, size);
    if (writer_.isOpened()) {
      codec_ = fourcc;
      return;
    }
  }
  throw RuntimeError(path_.string() + ": no video encoder available (tried H.264 and MPEG-4)");
}

VideoOutput::~VideoOutput() {
  if (!committed_) {
    writer_.release();
    std::error_code ec;
    fs::remove(partial_, ec);
  }
}

void VideoOutput::write(const cv::Mat& bgr8) { writer_.write(bgr8); }

void VideoOutput::commit() {
  writer_.release();
  std::error_code ec;
  fs::rename(partial_, path_, ec);
  if (ec) throw RuntimeError(path_.string() + ": cannot move the finished video into place (" + ec.message() + ")");
  committed_ = true;
}

FramesOutput::FramesOutput(fs::path dir) : dir_(std::move(dir)) {
  if (fs::exists(dir_)) throw InputError(dir_.string() + ": already exists; choose a new folder for the frames");
  partial_ = dir_.parent_path() / fmt::format(".{}.partial", dir_.filename().string());
  std::error_code ec;
  fs::remove_all(partial_, ec);
  if (!fs::create_directories(partial_, ec) || ec)
    throw InputError(dir_.string() + ": cannot create the folder (" + ec.message() + ")");
}

FramesOutput::~FramesOutput() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(partial_, ec);
  }
}

void FramesOutput::write(std::int64_t index, const cv::Mat& bgr8) {
  const fs::path file = partial_ / fmt::format("frame-{:06d}.png", index);
  if (!cv::imwrite(file.string(), bgr8)) throw RuntimeError(file.string() + ": cannot write PNG");
}

void FramesOutput::commit() {
  std::error_code ec;
  fs::rename(partial_, dir_, ec);
  if (ec) throw RuntimeError(dir_.string() + ": cannot move the frames into place (" + ec.message() + ")");
  committed_ = true;
}

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
  const fs::path partial = png.parent_path() / fmt::format(".{}.partial.png", png.filename().string());
  if (!cv::imwrite(partial.string(), sheet)) throw RuntimeError(png.string() + ": cannot write PNG");
  std::error_code ec;
  fs::rename(partial, png, ec);
  if (ec) throw RuntimeError(png.string() + ": cannot move the contact sheet into place (" + ec.message() + ")");
}

}  // namespace lumar::app
