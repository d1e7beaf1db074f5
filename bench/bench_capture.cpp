// Capture and recording costs per frame at 640x480 and 1280x720, on real footage
// (vtest.avi, resized): the hand-off from a capture thread through the bounded queue,
// the per-frame conversions a YUYV or MJPEG camera needs, and recording throughput
// through RecordingWriter (MJPEG q95 and FFV1, segments synced to disk). Baseline:
// cv::imencode of one JPEG at quality 95, the unavoidable core of an MJPEG recording.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "bench_report.h"
#include "lumar/capture/capture_thread.h"
#include "lumar/capture/jpeg_decoder.h"
#include "lumar/capture/recording_writer.h"

using namespace lumar;

namespace {

const std::vector<cv::Size> kSizes{{640, 480}, {1280, 720}};

// 30 real frames of vtest.avi at `size`.
const std::vector<cv::Mat>& frames(cv::Size size) {
  static std::map<int, std::vector<cv::Mat>> cache;
  auto& v = cache[size.width];
  if (v.empty()) {
    cv::VideoCapture cap(LUMAR_SOURCE_DIR "/../shared/data/video/vtest.avi", cv::CAP_FFMPEG);
    cv::Mat m;
    while (v.size() < 30 && cap.read(m)) {
      cv::Mat r;
      cv::resize(m, r, size, 0, 0, cv::INTER_AREA);
      v.push_back(r);
    }
  }
  return v;
}

// Frames from memory, as fast as the queue takes them: what is left is the thread and
// queue overhead (the Mat is shared, as a camera's converted frame would be handed on).
class MemorySource final : public capture::FrameSource {
 public:
  MemorySource(const std::vector<cv::Mat>& f, int count) : frames_(f), count_(count) {}
  bool read(capture::Frame& frame) override {
    if (n_ >= count_) return false;
    frame.image = frames_[std::size_t(n_) % frames_.size()];
    frame.time = n_;
    frame.index = n_++;
    return true;
  }
  cv::Size frame_size() const override { return frames_[0].size(); }
  double nominal_fps() const override { return 30; }
  std::string describe() const override { return "memory"; }

 private:
  const std::vector<cv::Mat>& frames_;
  int count_, n_ = 0;
};

std::string tag(cv::Size s) { return fmt::format("{}x{}", s.width, s.height); }

void register_size(cv::Size size) {
  const std::string t = tag(size);
  benchmark::RegisterBenchmark(("imencode/" + t).c_str(), [size](benchmark::State& state) {
    std::vector<std::uint8_t> out;
    std::size_t i = 0;
    for (auto _ : state) cv::imencode(".jpg", frames(size)[i++ % 30], out, {cv::IMWRITE_JPEG_QUALITY, 95});
  })->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark(("handoff/" + t).c_str(), [size](benchmark::State& state) {
    constexpr int kFrames = 2000;
    for (auto _ : state) {
      capture::FrameQueue queue(8, capture::QueuePolicy::KeepAll);
      capture::CaptureThread thread(std::make_unique<MemorySource>(frames(size), kFrames), queue);
      capture::Frame f;
      int n = 0;
      while (queue.pop(f, kNanosPerSecond)) ++n;
      thread.join();
      if (n != kFrames) state.SkipWithError("frames lost");
    }
    state.counters["frames"] = kFrames;
  })->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark(("yuyv_to_bgr/" + t).c_str(), [size](benchmark::State& state) {
    cv::Mat yuyv(size, CV_8UC2), bgr;
    cv::randu(yuyv, 0, 255);
    for (auto _ : state) cv::cvtColor(yuyv, bgr, cv::COLOR_YUV2BGR_YUYV);
  })->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark(("mjpeg_decode/" + t).c_str(), [size](benchmark::State& state) {
    std::vector<std::uint8_t> jpeg;
    cv::imencode(".jpg", frames(size)[0], jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
    for (auto _ : state) benchmark::DoNotOptimize(capture::decode_jpeg(jpeg));  // what the camera and replay use
  })->Unit(benchmark::kMillisecond);
  for (const char* codec : {"mjpeg", "ffv1"}) {
    benchmark::RegisterBenchmark((std::string("record_") + codec + "/" + t).c_str(), [size,
                                                                                      codec](benchmark::State& state) {
      constexpr int kFrames = 60;
      const auto dir = std::filesystem::temp_directory_path() / fmt::format("lumar-bench-capture-{}", ::getpid());
      for (auto _ : state) {
        state.PauseTiming();
        std::filesystem::remove_all(dir);
        state.ResumeTiming();
        capture::RecordingSettings s;
        s.codec = codec;
        s.size = size;
        capture::RecordingWriter w(dir, nlohmann::json::object(), s);
        for (int i = 0; i < kFrames; ++i) w.add_frame({frames(size)[std::size_t(i) % 30], i * 33'333'333, i});
        w.close();
      }
      std::filesystem::remove_all(dir);
      state.counters["frames"] = kFrames;
    })->Unit(benchmark::kMillisecond);
  }
}

}  // namespace

int main(int argc, char** argv) {
  for (cv::Size s : kSizes) {
    if (frames(s).size() != 30) {
      fmt::print(stderr, "cannot read 30 frames of ../shared/data/video/vtest.avi\n");
      return 2;
    }
    register_size(s);
  }
  benchmark::Initialize(&argc, argv);
  bench::CollectingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  bench::BenchReport report;
  report.name = "capture";
  report.title = "Capture and recording per frame (vtest.avi resized), ms";
  report.baseline = "JPEG encode q95 640x480";
  std::string note;
  for (cv::Size s : kSizes) {
    const std::string t = tag(s);
    // Per-frame times: the hand-off and record benchmarks run many frames per iteration.
    auto per_frame = [&](const std::string& key, double frames) {
      const auto* r = reporter.find(key + "/" + t);
      return r ? r->time_ms / frames : 0.0;
    };
    const double enc = per_frame("imencode", 1), hand = per_frame("handoff", 2000);
    const double mj = per_frame("record_mjpeg", 60), ff = per_frame("record_ffv1", 60);
    report.entries.push_back({"JPEG encode q95 " + t, enc});
    report.entries.push_back({"capture thread -> queue " + t, hand});
    report.entries.push_back({"YUYV -> BGR " + t, per_frame("yuyv_to_bgr", 1)});
    report.entries.push_back({"MJPEG decode " + t, per_frame("mjpeg_decode", 1)});
    report.entries.push_back({"record MJPEG q95 " + t, mj});
    report.entries.push_back({"record FFV1 " + t, ff});
    note += fmt::format("{}: hand-off {:.1f} us/frame; recording {:.0f} fps MJPEG, {:.0f} fps FFV1. ", t, hand * 1e3,
                        mj > 0 ? 1e3 / mj : 0.0, ff > 0 ? 1e3 / ff : 0.0);
  }
  report.note = note;
  report.compute_ratios();
  report.save(bench::results_dir());
  fmt::print("{}\n", note);
  return 0;
}
