#include "lumar/ui/overlay_window.h"

// epoxy declares GL for the renderer; ImGui's OpenGL 3 backend loads its own entry points.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <deque>
#include <glm/gtc/matrix_transform.hpp>

#include "lumar/base/error.h"
#include "lumar/base/stop_signal.h"
#include "lumar/calib/image_file.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/scene/scene.h"
#include "lumar/tracking/one_euro_filter.h"
#include "lumar/ui/debug_views.h"
#include "scene_editor.h"

namespace lumar::ui {

namespace {

using Clock = std::chrono::steady_clock;

// Dear ImGui's context and its GLFW and OpenGL 3 backends, for one window's life.
// `on_key` is installed first, so that ImGui's backend passes every key on to it.
class ImGuiSession {
 public:
  ImGuiSession(GLFWwindow* window, GLFWkeyfun on_key) {
    glfwSetKeyCallback(window, on_key);
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini beside the user's files
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 410 core");
  }
  ~ImGuiSession() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  ImGuiSession(const ImGuiSession&) = delete;
  ImGuiSession& operator=(const ImGuiSession&) = delete;
};

// One composite's time per stage, for the stats plot.
struct FrameStats {
  float total = 0, shadows = 0, objects = 0, background = 0, other = 0;
};

constexpr std::array<const char*, 2> kMethods{"volume", "sh9"};
constexpr double kNudgeM = 0.01, kTurnDeg = 5.0, kDragPx = 3.0;

class OverlayWindow {
 public:
  OverlayWindow(pipeline::ReplayOverlay& replay, const OverlayWindowSettings& settings,
                const std::function<void(const pipeline::OverlayFrame&)>& played)
      : replay_(replay),
        overlay_(replay.overlay()),
        window_(*replay.window()),
        settings_(settings),
        played_(played),
        editor_(replay.overlay()),
        imgui_(window_.glfw_window(), &OverlayWindow::on_key),
        playing_(!settings.paused),
        loop_(settings.loop) {
    frame_count_ = std::int64_t(replay_.replay().reader().frames().size());
    fps_ = std::max(1.0, replay_.replay().reader().video().fps);
    save_path_ = settings.save_scene.string();
    screenshot_path_ = settings.screenshot.string();
    features_ = overlay_.compositor().renderer().features();
    filtered_ = settings.pose_filter;
    glfwSetWindowUserPointer(window_.glfw_window(), this);
    if (!seek(0)) throw InputError("overlay: the recording's first frame cannot be read");
  }

  ~OverlayWindow() { glfwSetWindowUserPointer(window_.glfw_window(), nullptr); }
  OverlayWindow(const OverlayWindow&) = delete;
  OverlayWindow& operator=(const OverlayWindow&) = delete;

  void run() {
    while (!window_.should_close() && !done_ && !stop_requested()) {
      if (playing_)
        window_.poll_events();
      else
        window_.wait_events(0.05);  // idle while paused, awake for input
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      handle_mouse();
      handle_keys();
      panels();
      advance();
      if (dirty_) composite();
      ImGui::Render();
      const cv::Mat shown =
          debug_.any() && pose_ ? draw_debug_views(image_, overlay_.compositor(), *pose_, debug_) : image_;
      window_.present_in_corner(shown, [&] {
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        if (window_shot_) {
          window_shot_ = false;
          attempt("screenshot", [&] {
            calib::write_image_atomically(screenshot_path_, window_.read_back_buffer());
            say("saved the window to " + screenshot_path_, false);
          });
        }
      });
    }
  }

 private:
  // --- transport -------------------------------------------------------------------
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
    dirty_ = true;
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
    dirty_ = false;
    apply_lighting_switches();
    const pipeline::StageTimes before = overlay_.times();
    pose_ = replay_.camera_pose(frame_);
    const pipeline::OverlayFrame out = overlay_.composite(frame_, pose_);
    image_ = out.composite;
    const pipeline::StageTimes& t = overlay_.times();
    FrameStats s;
    s.shadows = float(t.shadows - before.shadows);
    s.objects = float(t.objects - before.objects);
    s.background = float(t.background - before.background + t.upload - before.upload);
    s.total = float(t.total() - before.total());
    s.other = s.total - s.shadows - s.objects - s.background;
    stats_.push_back(s);
    if (stats_.size() > 240) stats_.pop_front();
    // The first time the window reaches a frame in order (played, or stepped to): outputs,
    // and the frame budget.
    if (current_ == played_up_to_) {
      if (played_) played_(out);
      ++played_up_to_;
      if (settings_.max_frames > 0 && played_up_to_ >= settings_.max_frames) done_ = true;
    }
  }

  void apply_lighting_switches() {
    overlay_.compositor().set_shadows_enabled(shadows_, object_shadows_);
    overlay_.compositor().set_features(features_);
  }

  // --- placement -------------------------------------------------------------------
  std::optional<SurfacePoint> surface_under(const ImVec2& mouse) {
    if (!pose_) {
      say("no camera pose for this frame: nothing to place against", true);
      return std::nullopt;
    }
    return surface_at_pixel(editor_.proxy(), overlay_.compositor().output_camera(), *pose_,
                            glm::dvec2(mouse.x, mouse.y));
  }

  bool over_video(const ImVec2& p) const { return p.x >= 0 && p.y >= 0 && p.x < image_.cols && p.y < image_.rows; }

  void handle_mouse() {
    const ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureMouse || editor_.object_count() == 0) {
      pressed_ = false;
      return;
    }
    const std::size_t i = selected();
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left) && over_video(io.MousePos)) {
      pressed_ = true;
      dragging_ = false;
      press_pos_ = io.MousePos;
      press_pose_ = editor_.scene().objects[i].T_world_model;
      press_rest_ = editor_.rest(i);
      press_surface_ = surface_under(io.MousePos);
    }
    const bool released = pressed_ && ImGui::IsMouseReleased(ImGuiMouseButton_Left);
    if (pressed_ && (ImGui::IsMouseDown(ImGuiMouseButton_Left) || released)) {
      const float dx = io.MousePos.x - press_pos_.x, dy = io.MousePos.y - press_pos_.y;
      if (!dragging_ && dx * dx + dy * dy > kDragPx * kDragPx) dragging_ = true;
      // To where the mouse is, also on the frame it is let go.
      if (dragging_ && press_surface_)
        if (const auto here = surface_under(io.MousePos)) {
          // Along the surface it was grabbed on: the offset between the rays' two hits.
          glm::dvec3 offset = here->point - press_surface_->point;
          offset -= glm::dot(offset, press_rest_.normal) * press_rest_.normal;
          editor_.slide(i, press_pose_, press_rest_, offset);
          dirty_ = true;
        }
    }
    if (released) {
      pressed_ = false;
      if (!dragging_) {
        if (press_surface_) {
          editor_.place(i, *press_surface_);
          dirty_ = true;
        } else if (pose_) {
          say("the click's ray meets no proxy surface", true);
        }
      }
    }
    if (io.MouseWheel != 0 && over_video(io.MousePos)) {
      editor_.turn(i, kTurnDeg * io.MouseWheel);
      dirty_ = true;
    }
  }

  // Arrow keys slide the selected object along its surface, in the camera's right and
  // forward directions laid on it.
  void nudge(double right, double forward) {
    if (!pose_ || editor_.object_count() == 0) return;
    const std::size_t i = selected();
    const glm::dvec3 n = editor_.rest(i).normal;
    glm::dvec3 r = pose_->rotation * glm::dvec3(1, 0, 0), f = pose_->rotation * glm::dvec3(0, 0, 1);
    r = glm::normalize(r - glm::dot(r, n) * n);
    f = glm::normalize(f - glm::dot(f, n) * n);
    editor_.slide(i, editor_.scene().objects[i].T_world_model, editor_.rest(i), kNudgeM * (right * r + forward * f));
    dirty_ = true;
  }

  // Every key press, kept until the frame handles it: ImGui 1.86 samples keys once per
  // frame, and a press and release between two slow frames would be lost.
  struct KeyPress {
    int key = 0, mods = 0;
    bool repeat = false;
  };
  static void on_key(GLFWwindow* window, int key, int /*scancode*/, int action, int mods) {
    if (auto* self = static_cast<OverlayWindow*>(glfwGetWindowUserPointer(window)); self && action != GLFW_RELEASE)
      self->keys_.push_back({key, mods, action == GLFW_REPEAT});
  }

  void handle_keys() {
    std::vector<KeyPress> keys;
    keys.swap(keys_);
    if (ImGui::GetIO().WantCaptureKeyboard) return;  // typed into a field
    for (const KeyPress& k : keys) {
      const bool ctrl = k.mods & GLFW_MOD_CONTROL;
      const double step = (k.mods & GLFW_MOD_SHIFT) ? 5.0 : 1.0;
      switch (k.key) {
        case GLFW_KEY_LEFT:
          nudge(-step, 0);
          break;
        case GLFW_KEY_RIGHT:
          nudge(step, 0);
          break;
        case GLFW_KEY_UP:
          nudge(0, step);
          break;
        case GLFW_KEY_DOWN:
          nudge(0, -step);
          break;
        case GLFW_KEY_Q:
          turn_selected(kTurnDeg * step);
          break;
        case GLFW_KEY_E:
          turn_selected(-kTurnDeg * step);
          break;
        default:
          break;
      }
      if (k.repeat) continue;  // held: only the moves above repeat
      switch (k.key) {
        case GLFW_KEY_SPACE:
          playing_ = !playing_;
          break;
        case GLFW_KEY_PERIOD:
          playing_ = false, seek(current_ + 1);
          break;
        case GLFW_KEY_COMMA:
          playing_ = false, seek(current_ - 1);
          break;
        case GLFW_KEY_TAB:
          if (editor_.object_count() > 0) selected_ = (selected() + 1) % editor_.object_count();
          break;
        case GLFW_KEY_DELETE:
          remove_selected();
          break;
        case GLFW_KEY_H:
          shadows_ = !shadows_, dirty_ = true;
          break;
        case GLFW_KEY_S:
          if (ctrl) save_scene();
          break;
        case GLFW_KEY_O:
          if (ctrl) focus_mesh_field_ = true;
          break;
        case GLFW_KEY_F12:
          with_panels_ = ctrl;  // Ctrl+F12: the whole window
          save_screenshot();
          break;
        default:
          break;
      }
    }
  }

  void turn_selected(double degrees) {
    if (editor_.object_count() == 0) return;
    editor_.turn(selected(), degrees);
    dirty_ = true;
  }

  std::size_t selected() const { return std::min(selected_, std::max<std::size_t>(1, editor_.object_count()) - 1); }

  // --- actions that may fail: a message in the panel --------------------------------
  void say(const std::string& text, bool error) {
    message_ = text;
    message_error_ = error;
    (error ? spdlog::warn("{}", text) : spdlog::info("{}", text));
  }

  template <class F>
  void attempt(const char* what, F&& f) {
    try {
      f();
    } catch (const std::exception& e) {  // bad input, or a file that cannot be written: the window goes on
      say(std::string(what) + ": " + e.what(), true);
    }
  }

  void save_scene() {
    attempt("save", [&] {
      editor_.save(save_path_);
      say("saved the scene to " + save_path_, false);
    });
  }

  // The composite alone, or with `with_panels` the whole window once this frame is drawn.
  void save_screenshot() {
    attempt("screenshot", [&] {
      if (screenshot_path_.empty()) throw InputError("give a file name for the screenshot");
      if (with_panels_) {
        window_shot_ = true;
        return;
      }
      calib::write_image_atomically(screenshot_path_, image_);
      say("saved the composite to " + screenshot_path_, false);
    });
  }

  void add_object() {
    attempt("add", [&] {
      // On the surface under the middle of the view, else the middle of the movement box.
      const auto& camera = overlay_.compositor().output_camera();
      std::optional<SurfacePoint> at;
      if (pose_) at = surface_at_pixel(editor_.proxy(), camera, *pose_, {camera.cx, camera.cy});
      if (!at) {
        const Scene& m = editor_.scene().manifest;
        at = SurfacePoint{glm::dvec3(0.5 * (m.movement_min.x + m.movement_max.x), m.movement_min.y,
                                     0.5 * (m.movement_min.z + m.movement_max.z)),
                          glm::dvec3(0, 1, 0)};
      }
      selected_ = editor_.add(add_path_.data(), *at);
      dirty_ = true;
      say("added " + editor_.scene().objects[selected_].name, false);
    });
  }

  void remove_selected() {
    if (editor_.object_count() == 0) return;
    const std::string name = editor_.scene().objects[selected()].name;
    attempt("remove", [&] {
      editor_.remove(selected());
      dirty_ = true;
      say("removed " + name, false);
    });
  }

  // --- panels ------------------------------------------------------------------------
  void panels() {
    const ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(float(image_.cols), 0));
    ImGui::SetNextWindowSize(ImVec2(float(kPanelWidth), io.DisplaySize.y));
    ImGui::Begin("lumar", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    if (!message_.empty())
      ImGui::TextColored(message_error_ ? ImVec4(1.0f, 0.45f, 0.4f, 1.0f) : ImVec4(0.6f, 0.9f, 0.6f, 1.0f), "%s",
                         message_.c_str());
    transport_panel();
    objects_panel();
    lighting_panel();
    quality_panel();
    stats_panel();
    file_panel();
    ImGui::End();
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
                pose_ ? "pose known" : "no pose: video only");
  }

  void objects_panel() {
    if (!ImGui::CollapsingHeader("Objects", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const LoadedScene& scene = editor_.scene();
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
      const std::string label = scene.objects[i].name + (scene.objects[i].path.empty() ? "" : " (walks its path)");
      if (ImGui::Selectable(label.c_str(), i == selected())) selected_ = i;
    }
    if (scene.objects.empty()) ImGui::TextDisabled("no objects: add one below");
    if (focus_mesh_field_) ImGui::SetKeyboardFocusHere(), focus_mesh_field_ = false;
    const bool entered =
        ImGui::InputText("mesh", add_path_.data(), add_path_.size(), ImGuiInputTextFlags_EnterReturnsTrue);
    ImGui::SameLine();
    if (ImGui::Button("Add") || entered) add_object();
    if (scene.objects.empty()) return;
    const std::size_t i = selected();
    glm::vec3 albedo = scene.objects[i].albedo;
    if (ImGui::ColorEdit3("albedo", &albedo.x)) editor_.set_albedo(i, albedo), dirty_ = true;
    float scale = float(editor_.scale_factor(i));
    if (ImGui::SliderFloat("scale", &scale, 0.2f, 5.0f, "%.2fx", ImGuiSliderFlags_Logarithmic))
      editor_.set_scale_factor(i, scale), dirty_ = true;
    if (ImGui::Button("Turn -15")) editor_.turn(i, -15), dirty_ = true;
    ImGui::SameLine();
    if (ImGui::Button("Turn +15")) editor_.turn(i, 15), dirty_ = true;
    ImGui::SameLine();
    if (ImGui::Button("Remove")) remove_selected();
    const glm::dvec3 p = editor_.rest(selected()).point;
    ImGui::Text("rests at (%.3f, %.3f, %.3f) m", p.x, p.y, p.z);
    ImGui::TextDisabled("click: place  drag: slide  wheel, Q/E: turn");
    ImGui::TextDisabled("arrows: nudge 1 cm (shift: 5)  tab: next");
    ImGui::TextDisabled("space: play  ,/.: step  h: shadows  ctrl+O: mesh");
  }

  void lighting_panel() {
    if (!ImGui::CollapsingHeader("Lighting", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const std::string& method = editor_.scene().manifest.lighting.method;
    if (ImGui::BeginCombo("method", method.c_str())) {
      for (const char* m : kMethods)
        if (ImGui::Selectable(m, method == m))
          attempt("lighting", [&] {
            editor_.set_lighting_method(m);
            dirty_ = true;
          });
      ImGui::EndCombo();
    }
    dirty_ |= ImGui::Checkbox("shadows", &shadows_);
    ImGui::SameLine();
    dirty_ |= ImGui::Checkbox("objects shadow objects", &object_shadows_);
    dirty_ |= ImGui::Checkbox("antialiasing", &features_.antialiasing);
    ImGui::SameLine();
    dirty_ |= ImGui::Checkbox("self-occlusion", &features_.self_occlusion);
    dirty_ |= ImGui::Checkbox("noise", &features_.noise);
    ImGui::SameLine();
    dirty_ |= ImGui::Checkbox("blur", &features_.blur);
    float exposure = float(overlay_.exposure_scale());
    if (ImGui::SliderFloat("exposure", &exposure, 0.25f, 4.0f, "%.2fx", ImGuiSliderFlags_Logarithmic))
      overlay_.set_exposure_scale(exposure), dirty_ = true;
    bool truth = replay_.pose_source() == pipeline::PoseSource::Truth;
    if (ImGui::Checkbox("true poses (not the tracker's)", &truth))
      attempt("poses", [&] {
        replay_.set_pose_source(truth ? pipeline::PoseSource::Truth : pipeline::PoseSource::Tracker);
        dirty_ = true;
      });
  }

  // The knobs that trade speed for accuracy, the pose filter, and what to draw over the video.
  void quality_panel() {
    if (!ImGui::CollapsingHeader("Quality and debug views")) return;
    Compositor& compositor = overlay_.compositor();
    ShadowQuality q = compositor.shadow_quality();
    ImGui::SliderInt("emitter patches", &q.emitter_patches, 4, 256);
    const bool patches_done = ImGui::IsItemDeactivatedAfterEdit();
    ImGui::SliderInt("lines per patch", &q.lines_per_patch, 1, 32);
    if (patches_done || ImGui::IsItemDeactivatedAfterEdit())
      attempt("shadow quality", [&] {
        compositor.set_shadow_quality(q);
        dirty_ = true;
      });
    if (const LineShadows* lines = compositor.shadows())
      ImGui::Text("%zu radiosity lines, %u emitter patches", lines->lines().lines.size(), lines->lines().patch_count);
    bool adapt = overlay_.live_lighting() != nullptr;
    if (ImGui::Checkbox("follow the room's lighting (every 10 frames)", &adapt))
      overlay_.set_adapt_lighting_every(adapt ? 10 : 0), dirty_ = true;
    if (ImGui::Checkbox("One Euro filter on the tracker's poses", &filtered_))
      attempt("pose filter", [&] {
        replay_.set_pose_filter(filtered_ ? tracking::parse_pose_filter("one-euro") : std::nullopt);
        frames_.reset();  // the frames came from the replay just replaced
        seek(current_);
      });
    ImGui::Checkbox("proxy wireframe", &debug_.proxy_wireframe);
    ImGui::SameLine();
    ImGui::Checkbox("receivers", &debug_.receivers);
    ImGui::Checkbox("emitter samples", &debug_.emitters);
    ImGui::SameLine();
    ImGui::Checkbox("irradiance probes", &debug_.probes);
  }

  void stats_panel() {
    if (!ImGui::CollapsingHeader("Stats", ImGuiTreeNodeFlags_DefaultOpen) || stats_.empty()) return;
    std::vector<float> totals;
    FrameStats mean;
    for (const FrameStats& s : stats_) {
      totals.push_back(s.total);
      mean.total += s.total, mean.shadows += s.shadows, mean.objects += s.objects;
      mean.background += s.background, mean.other += s.other;
    }
    const float n = float(stats_.size());
    const std::string title =
        fmt::format("{:.1f} ms/frame ({:.1f} frames/s)", mean.total / n, 1000.0f * n / mean.total);
    ImGui::PlotLines("##total", totals.data(), int(totals.size()), 0, title.c_str(), 0.0f, FLT_MAX,
                     ImVec2(float(kPanelWidth) - 20.0f, 60.0f));
    ImGui::Text("objects %.1f  shadows %.1f  video %.1f  other %.1f ms", mean.objects / n, mean.shadows / n,
                mean.background / n, mean.other / n);
  }

  void file_panel() {
    if (!ImGui::CollapsingHeader("File", ImGuiTreeNodeFlags_DefaultOpen)) return;
    input_path("scene", save_path_);
    ImGui::SameLine();
    if (ImGui::Button("Save")) save_scene();
    input_path("image", screenshot_path_);
    ImGui::SameLine();
    if (ImGui::Button("Screenshot")) save_screenshot();
    ImGui::Checkbox("with the panels", &with_panels_);
  }

  static void input_path(const char* label, std::string& path) {
    std::array<char, 1024> buffer{};
    path.copy(buffer.data(), buffer.size() - 1);
    if (ImGui::InputText(label, buffer.data(), buffer.size())) path = buffer.data();
  }

  pipeline::ReplayOverlay& replay_;
  pipeline::Overlay& overlay_;
  gl::WindowContext& window_;
  OverlayWindowSettings settings_;
  std::function<void(const pipeline::OverlayFrame&)> played_;
  SceneEditor editor_;
  ImGuiSession imgui_;

  // transport
  std::unique_ptr<capture::FrameSource> frames_;
  capture::Frame frame_;
  std::int64_t position_ = 0, current_ = 0, frame_count_ = 0, played_up_to_ = 0;
  double fps_ = 24.0, speed_ = 1.0;
  bool playing_ = true, loop_ = true, done_ = false, dirty_ = true;
  Clock::time_point last_advance_ = Clock::now();
  std::optional<Pose> pose_;
  cv::Mat image_;

  // editing
  std::size_t selected_ = 0;
  bool pressed_ = false, dragging_ = false, focus_mesh_field_ = false;
  ImVec2 press_pos_;
  glm::dmat4 press_pose_{1.0};
  SurfacePoint press_rest_;
  std::optional<SurfacePoint> press_surface_;
  std::array<char, 1024> add_path_{};

  // lighting
  bool shadows_ = true, object_shadows_ = true, filtered_ = false;
  DebugViews debug_;
  gl::CompositeFeatures features_;

  std::vector<KeyPress> keys_;
  std::deque<FrameStats> stats_;
  std::string save_path_, screenshot_path_, message_;
  bool message_error_ = false, with_panels_ = false, window_shot_ = false;
};

}  // namespace

void run_overlay_window(pipeline::ReplayOverlay& replay, const OverlayWindowSettings& settings,
                        const std::function<void(const pipeline::OverlayFrame&)>& played) {
  if (!replay.window()) throw InputError("overlay: the interactive window needs an overlay made with a window");
  OverlayWindow(replay, settings, played).run();
}

}  // namespace lumar::ui
