#pragma once
// What the interactive window shows and does whatever feeds it frames (a replay with its
// transport, or a live camera with its status): the composite with its debug views, and
// the panels for objects, lighting, quality and files; placing objects with the mouse and
// the keyboard; messages for what failed. One ImGui frame per call of begin_frame ...
// present. Private to lumar_ui (overlay_window.cpp runs it).
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <deque>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <optional>
#include <string>

#include "lumar/base/error.h"
#include "lumar/calib/image_file.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/pipeline/overlay.h"
#include "lumar/pipeline/quality_choice.h"
#include "lumar/scene/scene.h"
#include "lumar/ui/debug_views.h"
#include "lumar/ui/overlay_window.h"
#include "scene_editor.h"

namespace lumar::ui {

// Dear ImGui's context and its GLFW and OpenGL 3 backends, for one window's life.
// `on_key` and `on_button` are installed first, so that ImGui's backend passes every key
// and button on to them; `on_cursor` is ours alone (ImGui 1.86 polls the pointer).
class ImGuiSession {
 public:
  ImGuiSession(GLFWwindow* window, GLFWkeyfun on_key, GLFWmousebuttonfun on_button, GLFWcursorposfun on_cursor) {
    glfwSetKeyCallback(window, on_key);
    glfwSetMouseButtonCallback(window, on_button);
    glfwSetCursorPosCallback(window, on_cursor);
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

// How the window's source chooses the quality knobs within a budget (quality_choice.h): a
// replay at once, on frames spread over the recording; a live camera on its next frames.
struct QualityChooser {
  std::function<void(const pipeline::QualityBudget&)> choose;
  std::function<std::string()> status;  // the last choice, or how far the next one has come
};

struct KeyPress {
  int key = 0, mods = 0;
  bool repeat = false;
};

class OverlayUi {
 public:
  OverlayUi(pipeline::Overlay& overlay, gl::WindowContext& window, const OverlayWindowSettings& settings)
      : overlay_(overlay),
        window_(window),
        editor_(overlay),
        imgui_(window.glfw_window(), &OverlayUi::on_key, &OverlayUi::on_button, &OverlayUi::on_cursor),
        save_path_(settings.save_scene.string()),
        screenshot_path_(settings.screenshot.string()) {
    features_ = overlay_.compositor().renderer().features();
    glfwSetWindowUserPointer(window_.glfw_window(), this);
    double x = 0, y = 0;
    glfwGetCursorPos(window_.glfw_window(), &x, &y);
    pointer_ = press_at_ = release_at_ = ImVec2(float(x), float(y));
  }
  ~OverlayUi() { glfwSetWindowUserPointer(window_.glfw_window(), nullptr); }
  OverlayUi(const OverlayUi&) = delete;
  OverlayUi& operator=(const OverlayUi&) = delete;

  void set_quality_chooser(QualityChooser chooser) { chooser_ = std::move(chooser); }

  // Starts a frame: a choice of quality asked for in the last one (which said so), ImGui's
  // frame, then the mouse (placing against the last composite's pose) and the keys, which
  // `source_keys` sees first (it returns true for those it used).
  void begin_frame(const std::function<bool(const KeyPress&)>& source_keys) {
    if (choose_pending_) {
      choose_pending_ = false;
      attempt("quality auto", [&] {
        chooser_.choose(pipeline::QualityBudget{.percent = budget_percent_});
        if (chooser_.status) say(chooser_.status(), false);
      });
      dirty_ = true;
    }
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    handle_mouse();
    handle_keys(source_keys);
  }

  // The panel beside the video: `source_panel` (transport, or live status) first.
  void panels(const std::function<void()>& source_panel) { panel_window(source_panel); }

  // The lighting switches, before each composite.
  void apply_switches() {
    overlay_.compositor().set_shadows_enabled(shadows_, object_shadows_);
    overlay_.compositor().set_features(features_);
  }

  // A new composite to show (and to place against), and its stage times.
  void show(const pipeline::OverlayFrame& out, const pipeline::StageTimes& before) {
    image_ = out.composite;
    pose_ = out.T_world_camera;
    const pipeline::StageTimes& t = overlay_.times();
    if (t.frames < before.frames) return;  // the times started again (a choice of quality)
    FrameStats s;
    s.shadows = float(t.shadows - before.shadows);
    s.objects = float(t.objects - before.objects);
    s.background = float(t.background - before.background + t.upload - before.upload);
    s.total = float(t.total() - before.total());
    s.other = s.total - s.shadows - s.objects - s.background;
    stats_.push_back(s);
    if (stats_.size() > 240) stats_.pop_front();
  }

  // Ends the frame: the composite with its debug views, the panels, the swap.
  void present() {
    ImGui::Render();
    const cv::Mat shown =
        debug_.any() && pose_ ? draw_debug_views(image_, overlay_.compositor(), *pose_, debug_) : image_;
    window_.present_in_corner(shown, [&] {
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      if (window_shot_ && ImGui::GetFrameCount() > 2) {  // ImGui lays a new window out in its first frames
        window_shot_ = false;
        attempt("screenshot", [&] {
          calib::write_image_atomically(screenshot_path_, window_.read_back_buffer());
          say("saved the window to " + screenshot_path_, false);
        });
      }
    });
  }

  // Something changed that the composite shows: composite again (a paused replay).
  bool dirty() const { return dirty_; }
  void set_dirty(bool dirty) { dirty_ = dirty; }
  bool has_image() const { return !image_.empty(); }
  const std::optional<Pose>& pose() const { return pose_; }

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

 private:
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
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left) && over_video(press_at_)) {
      pressed_ = true;
      dragging_ = false;
      press_pos_ = press_at_;
      press_pose_ = editor_.scene().objects[i].T_world_model;
      press_rest_ = editor_.rest(i);
      press_surface_ = surface_under(press_at_);
    }
    const bool released = pressed_ && ImGui::IsMouseReleased(ImGuiMouseButton_Left);
    if (pressed_ && (ImGui::IsMouseDown(ImGuiMouseButton_Left) || released)) {
      const ImVec2 mouse = released ? release_at_ : io.MousePos;
      const float dx = mouse.x - press_pos_.x, dy = mouse.y - press_pos_.y;
      if (!dragging_ && dx * dx + dy * dy > kDragPx * kDragPx) dragging_ = true;
      // To where the mouse is, and on the frame it is let go to where it was let go.
      if (dragging_ && press_surface_)
        if (const auto here = surface_under(mouse)) {
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
  static void on_key(GLFWwindow* window, int key, int /*scancode*/, int action, int mods) {
    if (auto* self = static_cast<OverlayUi*>(glfwGetWindowUserPointer(window)); self && action != GLFW_RELEASE)
      self->keys_.push_back({key, mods, action == GLFW_REPEAT});
  }

  // Where the pointer was when the left button went down and up, in the order the events
  // came. ImGui 1.86 reads the pointer once a frame, live: after a slow frame it is
  // already further along a drag than where the press was, and the object would jump.
  static void on_cursor(GLFWwindow* window, double x, double y) {
    if (auto* self = static_cast<OverlayUi*>(glfwGetWindowUserPointer(window)))
      self->pointer_ = ImVec2(float(x), float(y));
  }
  static void on_button(GLFWwindow* window, int button, int action, int /*mods*/) {
    auto* self = static_cast<OverlayUi*>(glfwGetWindowUserPointer(window));
    if (!self || button != GLFW_MOUSE_BUTTON_LEFT) return;
    (action == GLFW_PRESS ? self->press_at_ : self->release_at_) = self->pointer_;
  }

  void handle_keys(const std::function<bool(const KeyPress&)>& source_keys) {
    std::vector<KeyPress> keys;
    keys.swap(keys_);
    if (ImGui::GetIO().WantCaptureKeyboard) return;  // typed into a field
    for (const KeyPress& k : keys) {
      if (source_keys && source_keys(k)) continue;
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
        case GLFW_KEY_TAB:
          if (editor_.object_count() > 0) selected_ = (selected() + 1) % editor_.object_count();
          break;
        case GLFW_KEY_DELETE:
          remove_selected();
          break;
        case GLFW_KEY_H:
          shadows_ = !shadows_, dirty_ = true;
          break;
        case GLFW_KEY_A:
          choose_quality();
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

  // Said in this frame, done at the next one's start: the choice holds the window a few
  // seconds.
  void choose_quality() {
    if (!chooser_.choose) return;
    choose_pending_ = true;
    say(fmt::format("choosing the cheapest quality within {:.2f} % of the current one...", budget_percent_), false);
  }

  void turn_selected(double degrees) {
    if (editor_.object_count() == 0) return;
    editor_.turn(selected(), degrees);
    dirty_ = true;
  }

  std::size_t selected() const { return std::min(selected_, std::max<std::size_t>(1, editor_.object_count()) - 1); }

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

  void panel_window(const std::function<void()>& source_panel) {
    const ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(float(image_.cols), 0));
    ImGui::SetNextWindowSize(ImVec2(float(kPanelWidth), io.DisplaySize.y));
    ImGui::Begin("lumar", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    if (!message_.empty()) {  // wrapped: a choice of quality says a long line
      ImGui::PushStyleColor(ImGuiCol_Text,
                            message_error_ ? ImVec4(1.0f, 0.45f, 0.4f, 1.0f) : ImVec4(0.6f, 0.9f, 0.6f, 1.0f));
      ImGui::TextWrapped("%s", message_.c_str());
      ImGui::PopStyleColor();
    }
    if (source_panel) source_panel();
    objects_panel();
    lighting_panel();
    quality_panel();
    stats_panel();
    file_panel();
    ImGui::End();
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
    const bool entered = ImGui::InputText("mesh", add_path_.data(), add_path_.size(),
                                          ImGuiInputTextFlags_EnterReturnsTrue | ImGuiInputTextFlags_AutoSelectAll);
    ImGui::SameLine();
    if (ImGui::Button("Add") || entered) add_object();
    if (scene.objects.empty()) return;
    const std::size_t i = selected();
    glm::vec3 albedo = scene.objects[i].albedo;
    if (ImGui::ColorEdit3("albedo", &albedo.x)) editor_.set_albedo(i, albedo), dirty_ = true;
    bool bounce = scene.objects[i].bounce;
    if (ImGui::Checkbox("lights the room (bounce)", &bounce)) editor_.set_bounce(i, bounce), dirty_ = true;
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
    ImGui::TextDisabled("h: shadows  a: choose the quality");
    ImGui::TextDisabled("ctrl+O: mesh  ctrl+S: save  F12: screenshot");
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
    dirty_ |= ImGui::Checkbox("bounce (objects light the room)", &features_.bounce);
    ImGui::SameLine();
    dirty_ |= ImGui::Checkbox("contact shadows", &features_.contact);
    dirty_ |= ImGui::Checkbox("chroma subsampling (the camera's codec)", &features_.chroma);
    if (overlay_.shutter_s() > 0)  // the recording says how long its shutter was open
      dirty_ |= ImGui::Checkbox(fmt::format("motion blur ({:.0f} ms shutter)", 1e3 * overlay_.shutter_s()).c_str(),
                                &features_.motion_blur);
    float exposure = float(overlay_.exposure_scale());
    if (ImGui::SliderFloat("exposure", &exposure, 0.25f, 4.0f, "%.2fx", ImGuiSliderFlags_Logarithmic))
      overlay_.set_exposure_scale(exposure), dirty_ = true;
    if (const auto clipped = overlay_.objects_clipped(); clipped && *clipped > pipeline::Overlay::kClipWarnShare)
      ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.2f, 1.0f), "%.0f %% of the objects' pixels clip to white",
                         100.0 * *clipped);
  }

  // The knobs that trade speed for accuracy (pipeline::OverlayQuality, each applied as it
  // is let go), the choice of them within a budget, following the room's light, and what to
  // draw over the video.
  void quality_panel() {
    if (!ImGui::CollapsingHeader("Quality and debug views")) return;
    pipeline::OverlayQuality q = overlay_.quality();
    bool changed = false;
    int shading = int(q.shading);  // the order of ObjectShading
    if (ImGui::Combo("shading", &shading, "per pixel\0per vertex\0"))
      q.shading = ObjectShading(shading), changed = true;
    const IrradianceVolume* volume = overlay_.compositor().irradiance_volume().get();
    int lights = q.exact_lights.value_or(volume ? int(volume->lights.size()) : 0);
    ImGui::SliderInt("exact lights", &lights, 0, kMaxExactLights);
    if (ImGui::IsItemDeactivatedAfterEdit()) q.exact_lights = lights, changed = true;
    int map_n = q.shadow_map.value_or(volume ? volume->shadow_n : 0);
    if (ImGui::BeginCombo("shadow maps", fmt::format("{} px", map_n).c_str())) {
      for (int n = kMinShadowMapResolution; n <= kMaxShadowMapResolution; n *= 2)
        if (ImGui::Selectable(fmt::format("{} px", n).c_str(), n == map_n)) q.shadow_map = n, changed = true;
      ImGui::EndCombo();
    }
    ImGui::SliderInt("lines per patch", &q.shadows.lines_per_patch, 1, ShadowQuality::kMaxLinesPerPatch);
    changed |= ImGui::IsItemDeactivatedAfterEdit();
    ImGui::SliderInt("emitter patches", &q.shadows.emitter_patches, 4, 256);
    changed |= ImGui::IsItemDeactivatedAfterEdit();
    changed |= ImGui::Checkbox("contact shadows while moving", &q.shadows.contact_while_moving);
    float coverage = float(q.coverage_mesh_px);
    ImGui::SliderFloat("coverage meshes", &coverage, 0.0f, 4.0f, coverage > 0 ? "%.2f px" : "exact");
    if (ImGui::IsItemDeactivatedAfterEdit()) q.coverage_mesh_px = coverage, changed = true;
    if (changed)
      attempt("quality", [&] {
        overlay_.set_quality(q);  // new exact lights or maps: the volume is built again, or read from the cache
        dirty_ = true;
      });
    if (const LineShadows* lines = overlay_.compositor().shadows())
      ImGui::Text("%zu radiosity lines, %u emitter patches", lines->lines().lines.size(), lines->lines().patch_count);
    if (chooser_.choose) {
      ImGui::SliderFloat("budget", &budget_percent_, 0.25f, 10.0f, "%.2f %%", ImGuiSliderFlags_Logarithmic);
      if (ImGui::Button("Choose the cheapest within it (A)")) choose_quality();
      if (chooser_.status) ImGui::TextWrapped("%s", chooser_.status().c_str());
    }
    ImGui::TextDisabled("%s", q.describe().c_str());
    bool adapt = overlay_.live_lighting() != nullptr;
    if (ImGui::Checkbox("follow the room's lighting (every 10 frames)", &adapt))
      overlay_.set_adapt_lighting_every(adapt ? 10 : 0), dirty_ = true;
    if (const auto* lighting = overlay_.live_lighting())
      ImGui::Text("room %.2fx the map; %d/%d map cells seen, %d re-bakes (%.0f ms)%s", lighting->scale(),
                  lighting->adapter().measured_cells(),
                  lighting->adapter().settings().cell_cols * lighting->adapter().settings().cell_rows,
                  lighting->bakes(), lighting->last_bake_ms(), lighting->transition() ? ", fading in" : "");
    ImGui::Checkbox("proxy wireframe", &debug_.proxy_wireframe);
    ImGui::SameLine();
    ImGui::Checkbox("receivers", &debug_.receivers);
    ImGui::Checkbox("emitter samples", &debug_.emitters);
    ImGui::SameLine();
    ImGui::Checkbox("irradiance probes", &debug_.probes);
  }

  // Each stage's milliseconds over the last composites, one plot per stage on the
  // total's scale, with its mean.
  void stats_panel() {
    if (!ImGui::CollapsingHeader("Stats", ImGuiTreeNodeFlags_DefaultOpen) || stats_.empty()) return;
    const std::pair<const char*, float FrameStats::*> stages[] = {{"total", &FrameStats::total},
                                                                  {"objects", &FrameStats::objects},
                                                                  {"shadows", &FrameStats::shadows},
                                                                  {"video", &FrameStats::background},
                                                                  {"other", &FrameStats::other}};
    float top = 1.0f;
    for (const FrameStats& s : stats_) top = std::max(top, s.total);
    for (const auto& [name, member] : stages) {
      std::vector<float> values;
      float sum = 0;
      for (const FrameStats& s : stats_) values.push_back(s.*member), sum += s.*member;
      const float mean = sum / float(values.size());
      const std::string label = member == &FrameStats::total
                                    ? fmt::format("total {:.1f} ms ({:.1f} frames/s)", mean, 1000.0f / mean)
                                    : fmt::format("{} {:.1f} ms", name, mean);
      ImGui::PlotLines(("##" + std::string(name)).c_str(), values.data(), int(values.size()), 0, label.c_str(), 0.0f,
                       top, ImVec2(float(kPanelWidth) - 20.0f, member == &FrameStats::total ? 44.0f : 22.0f));
    }
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

  pipeline::Overlay& overlay_;
  gl::WindowContext& window_;
  SceneEditor editor_;
  ImGuiSession imgui_;
  std::optional<Pose> pose_;
  cv::Mat image_;
  bool dirty_ = true;

  // editing
  std::size_t selected_ = 0;
  bool pressed_ = false, dragging_ = false, focus_mesh_field_ = false;
  ImVec2 press_pos_, pointer_, press_at_, release_at_;
  glm::dmat4 press_pose_{1.0};
  SurfacePoint press_rest_;
  std::optional<SurfacePoint> press_surface_;
  std::array<char, 1024> add_path_{};

  // lighting
  bool shadows_ = true, object_shadows_ = true;
  gl::CompositeFeatures features_;
  DebugViews debug_;

  // quality
  QualityChooser chooser_;
  float budget_percent_ = float(pipeline::QualityBudget{}.percent);
  bool choose_pending_ = false;

  std::vector<KeyPress> keys_;
  std::deque<FrameStats> stats_;
  std::string save_path_, screenshot_path_, message_;
  bool message_error_ = false, with_panels_ = false, window_shot_ = false;
};

}  // namespace lumar::ui
