#pragma once
// The interactive overlay: a recording replayed, or a camera live, in a window with Dear
// ImGui panels beside the composite (docs/interactive.md):
//  - Transport (replay): play/pause, step, seek, speed, loop, the poses; or the camera's
//    and the tracker's status (live).
//  - Objects: select, add a mesh from a path, remove, albedo, scale.
//  - Placement: a click on the video rests the selected object where the click's ray meets
//    the proxy; a drag slides it over the surface; the wheel, Q/E or the panel's buttons
//    turn it about the surface's normal; the arrow keys nudge it.
//  - Lighting: the method, shadows, objects shadowing objects, the composite's features,
//    exposure, the poses (tracker or truth).
//  - Stats: time per stage over the last frames, frames per second.
//  - File: save the edited scene (atomically, keeping what the editor does not change) and
//    a screenshot.
// Bad input (a mesh that does not load, a file that cannot be written) is a message in the
// panel; the window keeps running.
#include <filesystem>
#include <functional>
#include <opencv2/core.hpp>

#include "lumar/pipeline/live_overlay.h"
#include "lumar/pipeline/replay_overlay.h"

namespace lumar::ui {

inline constexpr int kPanelWidth = 400;  // pixels right of the video

struct OverlayWindowSettings {
  std::filesystem::path save_scene;                           // File > Save and Ctrl+S write the edited scene here
  std::filesystem::path screenshot = "lumar-screenshot.png";  // File > Screenshot and F12
  bool paused = false;                                        // start paused on the first frame
  bool loop = true;                                           // play again from the start at the end
  bool pose_filter = false;  // the replay's tracker poses are filtered (the panel's switch)
  int max_frames = 0;        // > 0: close after playing this many frames (scripted runs)
};

// Runs `replay` (made with a window with pipeline::OverlaySettings::window_panel_width =
// kPanelWidth) until the window is closed, max_frames have played or a stop signal came
// (base/stop_signal.h). `played` sees each frame the first time the window reaches it in
// order (playing, or stepping), for outputs; edits and seeks composite again without
// calling it.
void run_overlay_window(pipeline::ReplayOverlay& replay, const OverlayWindowSettings& settings,
                        const std::function<void(const pipeline::OverlayFrame&)>& played);

// The live path in the window (`pipeline::LiveOverlay` made with a window with
// window_panel_width = kPanelWidth): the camera's and the tracker's status, and the same
// panels, one window frame per composited camera frame, until the source ends, a stop
// signal, or the window closes. `shown` sees each composited frame (for outputs).
// save_scene and screenshot apply; paused, loop, pose_filter and max_frames do not.
void run_live_overlay_window(pipeline::LiveOverlay& live, const OverlayWindowSettings& settings,
                             const std::function<void(const pipeline::OverlayFrame&)>& shown);

}  // namespace lumar::ui
