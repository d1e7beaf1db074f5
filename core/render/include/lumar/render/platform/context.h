#pragma once
// OpenGL 4.5 core contexts. The renderer does not care where its context comes from:
// a surfaceless EGL context (offline rendering, tests, no X server) or a GLFW window
// (the interactive viewer). GL objects belong to the context that was current when
// they were made; destroy them while it is current again.
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

struct GLFWwindow;

namespace lumar::gl {

class Context {
 public:
  virtual ~Context() = default;
  virtual void make_current() = 0;
  virtual std::string renderer_name() const = 0;  // GL_RENDERER + GL_VERSION
};

// EGL on Mesa's surfaceless platform (EGL_MESA_platform_surfaceless), OpenGL 4.5 core,
// current on the calling thread when returned. Needs no X server (works with DISPLAY
// unset); render into framebuffer objects. Throws RuntimeError when EGL or GL 4.5 is
// unavailable.
std::unique_ptr<Context> create_headless_context();
// Loads and initialises the driver behind create_headless_context (a tenth of a second
// on llvmpipe), so that a program may do it on another thread while it reads its
// inputs; thread-safe, and a no-op once done. A failure is left for
// create_headless_context to report.
void load_headless_driver();

// A GLFW window with an OpenGL 4.5 core context, current on the calling thread when
// constructed. Throws RuntimeError when no display can be opened.
class WindowContext : public Context {
 public:
  WindowContext(int width, int height, const std::string& title);
  ~WindowContext() override;
  WindowContext(const WindowContext&) = delete;
  WindowContext& operator=(const WindowContext&) = delete;

  void make_current() override;
  std::string renderer_name() const override;
  bool should_close() const;
  void poll_events();
  // Waits up to `seconds` for an event (input, a resize), then handles what came.
  void wait_events(double seconds);
  // Draws a BGR8 image (top row first) at its own size in the window's top-left corner,
  // clears the rest, calls `draw_over` (a user interface's draw calls, in the window's
  // framebuffer; may be empty) and swaps buffers. Window pixel (x, y) from the top-left
  // shows image pixel (x, y).
  void present_in_corner(const cv::Mat& bgr8, const std::function<void()>& draw_over);
  // What has been drawn into the back buffer so far (call it inside present_in_corner's
  // draw_over, after the user interface drew): the whole window, BGR8, top row first.
  cv::Mat read_back_buffer();
  // The GLFW window, for a user interface library's backend.
  GLFWwindow* glfw_window() { return window_handle(); }
  // What the window shows after the last present(), as the X server has it (for tests),
  // BGR8, top row first.
  cv::Mat read_front_buffer();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  GLFWwindow* window_handle();
};

}  // namespace lumar::gl
