#include "lumar/ui/overlay_window.h"

#include <chrono>

#include "lumar/base/stop_signal.h"
#include "lumar/tracking/one_euro_filter.h"
#include "overlay_ui.h"

namespace lumar::ui {

namespace {

using Clock = std::chrono::steady_clock;

// A recording in the window: the transport (play, pause, step, seek, speed, loop, the
// poses) over the shared panels.
class ReplayWindow {
 public:
  ReplayWindow(pipeline::ReplayOverlay& replay, const OverlayWindowSettings& settings,
               const std::function<void(const pipeline::OverlayFrame&)>& played)
      : replay_(replay),
        overlay_(replay.overlay()),
        window_(*replay.window()),
        settings_(settings),
        played_(played),
        ui_(replay.overlay(), *replay.window(), settings),
        playing_(!settings.paused),
        loop_(settings.loop),
        filtered_(settings.pose_filter) {
    frame_count_ = std::int64_t(replay_.replay().reader().frames().size());
    fps_ = std::max(1.0, replay_.replay().reader().video().fps);
    if (!seek(0)) throw InputError("overlay: the recording's first frame cannot be read");
    ui_.set_quality_chooser({[this](const pipeline::QualityBudget& budget) { replay_.choose_quality(budget); },
                             [this] { return replay_.quality_choice() ? replay_.quality_choice()->describe() : ""; }});
  }

  void run() {
    while (!window_.should_close() && !done_ && !stop_requested()) {
      if (playing_)
        window_.poll_events();
      else
        window_.wait_events(0.05);  // idle while paused, awake for input
      ui_.begin_frame([&](const KeyPress& k) { return transport_key(k); });
      ui_.panels([&] { transport_panel(); });
      advance();
      if (ui_.dirty()) composite();
      ui_.present();
    }
  }

 private:
  // Reads frame `index` (0-based in the recording's order), reopening the video to go back.
  bool seek(std::int64_t index) {
    index = std::clamp<std::int64_t>(index, 0, std::max<std::int64_t>(0, frame_count_ - 1));
    if (!frames_ || index < position_) {
      frames_ = replay_.replay().open_frames();
      position_ = 0;
    }
    capture::Frame f;
    while (position_ <= index) {
      if (!frames_->read(f)) return false;
      ++position_;
    }
    frame_ = std::move(f);
    current_ = index;
    ui_.set_dirty(true);
    return true;
  }

  void advance() {
    if (!playing_) return;
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last_advance_).count() < 1.0 / (fps_ * speed_)) return;
    last_advance_ = now;
    if (current_ + 1 < frame_count_) {
      if (!seek(current_ + 1)) playing_ = false;
    } else if (loop_) {
      seek(0);
    } else {
      playing_ = false;
    }
  }

  void composite() {
    ui_.set_dirty(false);
    ui_.apply_switches();
    const pipeline::StageTimes before = overlay_.times();
    const std::optional<Pose> pose = replay_.camera_pose(frame_);
    const pipeline::OverlayFrame out = overlay_.composite(frame_, pose, replay_.shutter_cameras(frame_, pose));
    ui_.show(out, before);
    if (overlay_.compositor().settling()) ui_.set_dirty(true);  // paused: the contact shadows still to come
    // The first time the window reaches a frame in order (played, or stepped to): outputs,
    // and the frame budget.
    if (current_ == played_up_to_) {
      if (played_) played_(out);
      ++played_up_to_;
      if (settings_.max_frames > 0 && played_up_to_ >= settings_.max_frames) done_ = true;
    }
  }

  bool transport_key(const KeyPress& k) {
    if (k.repeat) return false;
    switch (k.key) {
      case GLFW_KEY_SPACE:
        playing_ = !playing_;
        return true;
      case GLFW_KEY_PERIOD:
        playing_ = false, seek(current_ + 1);
        return true;
      case GLFW_KEY_COMMA:
        playing_ = false, seek(current_ - 1);
        return true;
      default:
        return false;
    }
  }

  void transport_panel() {
    if (!ImGui::CollapsingHeader("Transport", ImGuiTreeNodeFlags_DefaultOpen)) return;
    if (ImGui::Button(playing_ ? "Pause" : "Play")) playing_ = !playing_;
    ImGui::SameLine();
    if (ImGui::Button("<")) playing_ = false, seek(current_ - 1);
    ImGui::SameLine();
    if (ImGui::Button(">")) playing_ = false, seek(current_ + 1);
    ImGui::SameLine();
    ImGui::Checkbox("loop", &loop_);
    int frame = int(current_);
    if (ImGui::SliderInt("frame", &frame, 0, int(std::max<std::int64_t>(0, frame_count_ - 1)))) seek(frame);
    float speed = float(speed_);
    if (ImGui::SliderFloat("speed", &speed, 0.1f, 4.0f, "%.2fx", ImGuiSliderFlags_Logarithmic)) speed_ = speed;
    ImGui::Text("%.2f s of %.2f s, %s", nanos_to_seconds(frame_.time),
                nanos_to_seconds(replay_.replay().reader().frames().back().time),
                ui_.pose() ? "pose known" : "no pose: video only");
    // The order of pipeline::PoseSource.
    int source = int(replay_.pose_source());
    if (ImGui::Combo("poses", &source, "tracker\0tracker steadied by the video\0truth\0"))
      ui_.attempt("poses", [&] {
        replay_.set_pose_source(pipeline::PoseSource(source));
        ui_.set_dirty(true);
      });
    if (ImGui::Checkbox("One Euro filter on the tracker's poses", &filtered_))
      ui_.attempt("pose filter", [&] {
        replay_.set_pose_filter(filtered_ ? tracking::parse_pose_filter("one-euro") : std::nullopt);
        frames_.reset();  // the frames came from the replay just replaced
        seek(current_);
      });
    ImGui::TextDisabled("space: play  ,/.: step");
  }

  pipeline::ReplayOverlay& replay_;
  pipeline::Overlay& overlay_;
  gl::WindowContext& window_;
  OverlayWindowSettings settings_;
  std::function<void(const pipeline::OverlayFrame&)> played_;
  OverlayUi ui_;
  std::unique_ptr<capture::FrameSource> frames_;
  capture::Frame frame_;
  std::int64_t position_ = 0, current_ = 0, frame_count_ = 0, played_up_to_ = 0;
  double fps_ = 24.0, speed_ = 1.0;
  bool playing_ = true, loop_ = true, filtered_ = false, done_ = false;
  Clock::time_point last_advance_ = Clock::now();
};

// A live camera in the window: the camera's and the tracker's status over the shared
// panels; one window frame per composited camera frame.
class LiveWindow {
 public:
  LiveWindow(pipeline::LiveOverlay& live, const OverlayWindowSettings& settings)
      : live_(live), ui_(live.overlay(), *live.overlay().window(), settings) {
    ui_.set_quality_chooser({[this](const pipeline::QualityBudget& budget) { live_.choose_quality(budget); },
                             [this]() -> std::string {
                               if (const auto [have, need] = live_.quality_probes(); need > 0)
                                 return fmt::format("collecting frames to choose on: {} of {}", have, need);
                               return live_.quality_choice() ? live_.quality_choice()->describe() : "";
                             }});
  }

  // One camera frame: the panels, the composite, the swap. False: the window was closed.
  bool frame(const pipeline::OverlayFrame& out, const pipeline::StageTimes& before) {
    const auto now = Clock::now();
    if (shown_ > 0) {
      const double dt = std::chrono::duration<double>(now - last_frame_).count();
      rate_ = rate_ > 0 ? 0.9 * rate_ + 0.1 / std::max(dt, 1e-3) : 1.0 / std::max(dt, 1e-3);
    }
    last_frame_ = now;
    ++shown_;
    ui_.begin_frame({});
    ui_.panels([&] { status_panel(); });
    ui_.show(out, before);
    ui_.present();
    ui_.apply_switches();  // for the next frame
    return !live_.overlay().window()->should_close();
  }

 private:
  void status_panel() {
    if (!ImGui::CollapsingHeader("Camera and tracker", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const pipeline::LiveLoop& loop = live_.loop();
    const pipeline::LiveLoopStats& s = loop.stats();
    ImGui::Text("%s", loop.describe_source().c_str());
    ImGui::Text("%.1f frames/s shown (source %.0f), %llu stale skipped", rate_, live_.fps(),
                static_cast<unsigned long long>(s.queue.stale_dropped));
    ImGui::Text("%llu frames: %llu without a pose, %llu extrapolated", static_cast<unsigned long long>(s.frames),
                static_cast<unsigned long long>(s.without_pose), static_cast<unsigned long long>(s.extrapolated));
    if (const tracking::TrackerDriver* driver = loop.driver()) {
      const tracking::DriverStatus t = driver->status();
      const double age_ms = t.last_record > 0 ? nanos_to_seconds(monotonic_now() - t.last_record) * 1e3 : -1;
      ImGui::Text("tracker: %llu records, newest %.0f ms old", static_cast<unsigned long long>(t.records), age_ms);
      ImGui::Text("%llu reconnections, %llu watchdog faults",
                  static_cast<unsigned long long>(t.connects > 0 ? t.connects - 1 : 0),
                  static_cast<unsigned long long>(t.watchdog_faults));
      if (!t.message.empty()) ImGui::TextWrapped("%s", t.message.c_str());
    } else {
      ImGui::TextDisabled("no tracker: the recording's own poses, or none");
    }
  }

  pipeline::LiveOverlay& live_;
  OverlayUi ui_;
  Clock::time_point last_frame_ = Clock::now();
  std::uint64_t shown_ = 0;
  double rate_ = 0;
};

}  // namespace

void run_overlay_window(pipeline::ReplayOverlay& replay, const OverlayWindowSettings& settings,
                        const std::function<void(const pipeline::OverlayFrame&)>& played) {
  if (!replay.window()) throw InputError("overlay: the interactive window needs an overlay made with a window");
  ReplayWindow(replay, settings, played).run();
}

void run_live_overlay_window(pipeline::LiveOverlay& live, const OverlayWindowSettings& settings,
                             const std::function<void(const pipeline::OverlayFrame&)>& shown) {
  if (!live.overlay().window()) throw InputError("overlay: the interactive window needs an overlay made with a window");
  LiveWindow window(live, settings);
  pipeline::StageTimes before = live.overlay().times();
  live.run([&](const pipeline::OverlayFrame& out) {
    if (shown) shown(out);
    const bool open = window.frame(out, before);
    before = live.overlay().times();
    return open;
  });
}

}  // namespace lumar::ui
