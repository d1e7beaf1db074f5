// The interactive window, driven as a user drives it: the real `lumar overlay --window`
// on the test's X server (ctest runs this under xvfb-run: ui.overlay_window), with
// xdotool's clicks, drag, wheel and keys. What the window saves is checked against the
// floor plane met by each click's ray (computed here in closed form, not with the
// window's Embree picking), and its composites against a headless replay of the scene it
// saved.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

#include "lumar/base/color.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/pipeline/replay_overlay.h"
#include "lumar/scene/loaded_scene.h"
#include "test_paths.h"

extern char** environ;

namespace lumar {
namespace {

using namespace std::chrono_literals;

// `lumar` running as a child with its output in a log; killed if the test ends first.
class Child {
 public:
  Child(const std::vector<std::string>& args, const std::filesystem::path& log) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Child() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  bool running() {
    if (exited_) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) exited_ = true, status_ = status;
    return !exited_;
  }
  // Sends `signal` and waits; the exit status, or -1 on a crash.
  int stop(int signal) {
    if (running()) {
      kill(pid_, signal);
      waitpid(pid_, &status_, 0);
      exited_ = true;
    }
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1;
  }
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
  int status_ = 0;
};

std::string xdotool(const std::string& args) {
  const std::string command = "xdotool " + args + " 2>&1";
  std::string out;
  if (FILE* p = popen(command.c_str(), "r")) {
    char buffer[256];
    while (fgets(buffer, sizeof buffer, p)) out += buffer;
    pclose(p);
  }
  return out;
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Where the ray through pixel (u, v) of the undistorted camera meets the floor, y = 0.
glm::dvec3 floor_hit(const CameraIntrinsics& camera, const Pose& T_world_camera, double u, double v) {
  const glm::dvec3 d =
      T_world_camera.rotation * glm::dvec3((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1);
  const glm::dvec3 o = T_world_camera.translation;
  return o + (-o.y / d.y) * d;
}

glm::dvec2 project(const CameraIntrinsics& camera, const Pose& T_world_camera, const glm::dvec3& p) {
  const glm::dvec3 c = T_world_camera.inverse().apply(p);
  std::vector<cv::Point2d> out;
  cv::projectPoints(std::vector<cv::Point3d>{{c.x, c.y, c.z}}, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                    cv::Mat(camera.camera_matrix()), cv::noArray(), out);
  return {out[0].x, out[0].y};
}

// The middle of the bottom of the object's world box: where it stands.
glm::dvec3 footprint(const LoadedObject& o) {
  const auto [lo, hi] = transformed(o.model, o.T_world_model).bounds();
  return {0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z)};
}

glm::dquat rotation_of(const glm::dmat4& T) {
  const glm::dmat3 M(T);
  return glm::normalize(glm::quat_cast(M / glm::length(M[0])));
}

class OverlayWindow : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_NE(std::getenv("DISPLAY"), nullptr) << "run under xvfb-run (ctest: ui.overlay_window)";
    ASSERT_EQ(std::system("command -v xdotool >/dev/null"), 0) << "xdotool is missing: scripts/install-deps.sh";
  }

  // Waits until `ready` holds, for up to `seconds` (times the build's slowness).
  template <class F>
  bool wait_until(F&& ready, double seconds) {
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds * test::time_scale());
    while (std::chrono::steady_clock::now() < deadline) {
      if (ready()) return true;
      std::this_thread::sleep_for(100ms);
    }
    return ready();
  }

  // Holds `keys` ("ctrl+o") down for a while as the X server's test extension types them:
  // the modifiers first and released last, so that the key's autorepeat never comes
  // without them (a bare "o" would be typed into a focused field). 0.4 s: the window
  // queues its own shortcuts, but ImGui's text field samples keys once a frame, and a
  // paused window's frames are short.
  void press(const std::string& keys) {
    std::vector<std::string> parts;
    for (std::size_t start = 0;;) {
      const std::size_t plus = keys.find('+', start);
      parts.push_back(keys.substr(start, plus - start));
      if (plus == std::string::npos) break;
      start = plus + 1;
    }
    for (const auto& k : parts) xdotool("keydown " + k);
    std::this_thread::sleep_for(400ms);
    for (auto k = parts.rbegin(); k != parts.rend(); ++k) xdotool("keyup " + *k);
    std::this_thread::sleep_for(std::chrono::milliseconds(100 * test::time_scale()));
  }

  void click_at(int x, int y, int button = 1) {
    xdotool("mousemove --window " + window_ + " " + std::to_string(x) + " " + std::to_string(y));
    xdotool("mousedown " + std::to_string(button));
    std::this_thread::sleep_for(std::chrono::milliseconds(250 * test::time_scale()));
    xdotool("mouseup " + std::to_string(button));
  }

  // Ctrl+S, then the saved scene moved to `name` once it is there.
  std::filesystem::path save_as(const std::string& name) {
    std::filesystem::remove(saved_);
    press("ctrl+s");
    EXPECT_TRUE(wait_until([&] { return std::filesystem::exists(saved_); }, 30)) << read_text(log_);
    const auto to = scratch_.dir / name;
    std::filesystem::rename(saved_, to);
    return to;
  }

  // F12: the composite, moved to `name`.
  cv::Mat screenshot(const std::string& name) {
    std::filesystem::remove(shot_);
    press("F12");
    EXPECT_TRUE(wait_until([&] { return std::filesystem::exists(shot_); }, 30)) << read_text(log_);
    const auto to = scratch_.dir / name;
    std::filesystem::rename(shot_, to);
    return cv::imread(to.string(), cv::IMREAD_COLOR);
  }

  void pause_for_frames() { std::this_thread::sleep_for(std::chrono::milliseconds(600 * test::time_scale())); }

  test::Scratch scratch_{"overlay-window"};
  std::filesystem::path saved_ = scratch_.dir / "scene.json", shot_ = scratch_.dir / "shot.png",
                        log_ = scratch_.dir / "log.txt";
  std::string window_;
};

TEST_F(OverlayWindow, PlaceSlideTurnShadowsSaveAndBadMeshes) {
  const auto recording = test::source_dir() / "recordings/walk";
  Child lumar(
      {test::lumar_binary().string(), "overlay", "--recording", recording.string(), "--window", "--paused", "--poses",
       "truth", "--without", "noise", "--save-scene", saved_.string(), "--screenshot", shot_.string()},
      log_);
  ASSERT_GT(lumar.pid(), 0);
  ASSERT_TRUE(wait_until(
      [&] {
        window_ = xdotool("search --name \"lumar overlay\"");
        window_ = window_.substr(0, window_.find('\n'));
        return !window_.empty() || !lumar.running();
      },
      120));
  ASSERT_TRUE(lumar.running()) << read_text(log_);
  // Keys go to the window under the pointer (no window manager).
  xdotool("mousemove --window " + window_ + " 320 240");
  std::this_thread::sleep_for(std::chrono::milliseconds(2000 * test::time_scale()));  // its first frame
  save_as("first.json");                                                              // the window is up and takes keys

  const capture::RecordingReplay replay(recording);
  const Pose pose = *replay.true_camera_pose(0);
  const CameraIntrinsics camera = replay.session().camera.without_distortion();

  // A click on the floor rests the selected object (the walker) there.
  const glm::dvec2 click(220, 400);
  click_at(220, 400);
  pause_for_frames();
  const LoadedScene placed = load_scene_files(save_as("placed.json"));
  ASSERT_EQ(placed.objects.size(), 2u);
  EXPECT_TRUE(placed.objects[0].path.empty());  // placed, it stops walking
  const glm::dvec3 foot = footprint(placed.objects[0]);
  const glm::dvec2 seen = project(camera, pose, foot);
  EXPECT_LT(glm::distance(seen, click), 2.0) << "the object stands at pixel " << seen.x << ", " << seen.y;
  EXPECT_NEAR(foot.y, 0.0, 1e-3);
  const glm::dvec3 hit = floor_hit(camera, pose, click.x, click.y);
  EXPECT_LT(glm::distance(foot, hit), 0.002) << "floor hit " << hit.x << ", " << hit.z;

  // A 100 px drag slides it along the floor by what the rays' floor hits say. The press
  // and the first move, and the last move and the release, come in one xdotool call each:
  // faster than a frame, as a quick hand on a slow machine (the window reads the pointer
  // once a frame, so it must take the press's and release's own positions).
  const auto move_to = [&](int x) { return "mousemove --window " + window_ + " " + std::to_string(x) + " 400"; };
  xdotool("mousedown 1 " + move_to(240));
  for (int x = 260; x <= 300; x += 20) {
    std::this_thread::sleep_for(std::chrono::milliseconds(150 * test::time_scale()));
    xdotool(move_to(x));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(150 * test::time_scale()));
  xdotool(move_to(320) + " mouseup 1");
  pause_for_frames();
  const LoadedScene dragged = load_scene_files(save_as("dragged.json"));
  const glm::dvec3 moved = glm::dvec3(dragged.objects[0].T_world_model[3] - placed.objects[0].T_world_model[3]);
  const glm::dvec3 predicted = floor_hit(camera, pose, 320, 400) - hit;
  EXPECT_LT(glm::distance(moved, predicted), 0.002) << "moved " << moved.x << ", " << moved.y << ", " << moved.z
                                                    << "; the rays say " << predicted.x << ", " << predicted.z;
  EXPECT_GT(glm::length(predicted), 0.05);
  std::printf("click: the object stands %.3f px from the click, %.2f mm from its ray's floor hit\n",
              glm::distance(seen, click), 1e3 * glm::distance(foot, hit));
  std::printf("drag of 100 px: moved %.1f mm, %.3f mm from the rays' prediction\n", 1e3 * glm::length(moved),
              1e3 * glm::distance(moved, predicted));

  // The wheel turns it 5 degrees about the floor's normal, where it stands.
  xdotool("mousemove --window " + window_ + " 320 300");
  xdotool("click 4");
  pause_for_frames();
  const auto turned_file = save_as("turned.json");
  const LoadedScene turned = load_scene_files(turned_file);
  const glm::dquat turn =
      rotation_of(turned.objects[0].T_world_model) * glm::inverse(rotation_of(dragged.objects[0].T_world_model));
  EXPECT_NEAR(glm::degrees(glm::angle(turn)), 5.0, 0.01);
  EXPECT_NEAR(std::abs(glm::axis(turn).y), 1.0, 1e-6);
  // About the vertical through where it stood: that point stays put.
  const glm::dvec3 stood = footprint(dragged.objects[0]);
  const glm::dvec3 after_turn(turned.objects[0].T_world_model *
                              (glm::inverse(dragged.objects[0].T_world_model) * glm::dvec4(stood, 1.0)));
  EXPECT_LT(glm::distance(after_turn, stood), 1e-6);

  // Shadows on, then off (H): each composite is the headless replay's of the saved scene.
  pipeline::ReplayOverlaySettings settings;
  settings.scene = turned_file;
  settings.poses = pipeline::PoseSource::Truth;
  settings.overlay.features.noise = false;
  pipeline::ReplayOverlay headless(recording, settings);
  cv::Mat want_on, want_off;
  headless.run(1, [&](const pipeline::OverlayFrame& f) { return want_on = f.composite.clone(), true; });
  headless.compositor().set_shadows_enabled(false);
  headless.run(1, [&](const pipeline::OverlayFrame& f) { return want_off = f.composite.clone(), true; });
  // The replay's object never moved, so its contact shadows are there at once; the
  // window's come once the turned object has stood still for a few frames, paused or not.
  cv::Mat shown_on;
  wait_until(
      [&] {
        shown_on = screenshot("on.png");
        return shown_on.size() == want_on.size() && cv::PSNR(shown_on, want_on) >= 50.0;
      },
      10);
  ASSERT_EQ(shown_on.size(), want_on.size());
  EXPECT_GE(cv::PSNR(shown_on, want_on), 50.0);
  press("h");
  pause_for_frames();
  const cv::Mat shown_off = screenshot("off.png");
  EXPECT_GE(cv::PSNR(shown_off, want_off), 50.0);
  // The floor beside the object's feet: darker with the shadow, as the replay says.
  const glm::dvec2 f = project(camera, pose, footprint(turned.objects[0]));
  const cv::Rect patch = cv::Rect(int(f.x) - 40, int(f.y) - 10, 80, 30) & cv::Rect(0, 0, 640, 480);
  double ratio_shown = 0, ratio_want = 0;
  int n = 0;
  for (int y = patch.y; y < patch.y + patch.height; ++y)
    for (int x = patch.x; x < patch.x + patch.width; ++x) {
      const cv::Vec3b a = shown_on.at<cv::Vec3b>(y, x), b = shown_off.at<cv::Vec3b>(y, x);
      const cv::Vec3b c = want_on.at<cv::Vec3b>(y, x), d = want_off.at<cv::Vec3b>(y, x);
      if (b[1] < 20 || d[1] < 20) continue;
      ratio_shown += srgb_to_linear(a[1] / 255.0) / srgb_to_linear(b[1] / 255.0);
      ratio_want += srgb_to_linear(c[1] / 255.0) / srgb_to_linear(d[1] / 255.0);
      ++n;
    }
  ASSERT_GT(n, 500);
  ratio_shown /= n, ratio_want /= n;
  EXPECT_LT(ratio_shown, 0.97) << "the shadow should darken the floor by the feet";
  EXPECT_NEAR(ratio_shown, ratio_want, 0.01);
  std::printf(
      "shadows on/off: PSNR %.1f / %.1f dB against the headless replay of the saved scene; floor by the "
      "feet %.3f of its light (replay %.3f)\n",
      cv::PSNR(shown_on, want_on), cv::PSNR(shown_off, want_off), ratio_shown, ratio_want);

  // A: the cheapest knobs within the panel's budget (1.5 %), chosen on frames spread over
  // the recording; the window goes on at them, close to full quality's composite (the
  // choice's own measure, in the log, is per region; a PSNR over the frame is a coarser
  // check that it shows the same scene, with the same edits and switches).
  press("a");
  ASSERT_TRUE(wait_until([&] { return read_text(log_).find(" trials on 7 frames") != std::string::npos; }, 300))
      << read_text(log_);
  pause_for_frames();
  const cv::Mat chosen = screenshot("chosen.png");
  ASSERT_TRUE(lumar.running()) << read_text(log_);
  EXPECT_NE(read_text(log_).find("(the reference)"), std::string::npos);
  EXPECT_GE(cv::PSNR(chosen, shown_off), 35.0);
  std::printf("quality chosen in the window: PSNR %.1f dB against full quality's composite\n",
              cv::PSNR(chosen, shown_off));

  // A mesh that does not load, and a file that is not a mesh: a message, and it goes on.
  const auto not_a_mesh = scratch_.dir / "not_a_mesh.ply";
  std::ofstream(not_a_mesh) << "this is not a mesh\n";
  for (const std::string& path : {std::string("/nonexistent/figure.ply"), not_a_mesh.string()}) {
    press("ctrl+o");  // focuses the mesh field with its text selected: typing replaces it
    pause_for_frames();
    xdotool("type --delay 30 '" + path + "'");
    press("Return");
    pause_for_frames();
  }
  xdotool("mousemove --window " + window_ + " 320 240");
  ASSERT_TRUE(lumar.running()) << read_text(log_);
  const LoadedScene after = load_scene_files(save_as("after.json"));
  EXPECT_EQ(after.objects.size(), 2u);
  const std::string log = read_text(log_);
  EXPECT_NE(log.find("add: /nonexistent/figure.ply"), std::string::npos) << log;
  EXPECT_NE(log.find("add: " + not_a_mesh.string()), std::string::npos) << log;

  // A stop signal closes it: interrupted, nothing half-written.
  EXPECT_EQ(lumar.stop(SIGTERM), 130) << read_text(log_);
}

}  // namespace
}  // namespace lumar
