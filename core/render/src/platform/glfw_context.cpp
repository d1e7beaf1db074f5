// The interactive window: GLFW with an OpenGL 4.5 core context (GLX on X11).
#include <epoxy/gl.h>
// epoxy provides the GL declarations; GLFW must not include its own.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <mutex>
#include <string>

#include "gl_util.h"
#include "lumar/base/error.h"
#include "lumar/render/platform/context.h"
#include "platform/x11_window_image.h"

namespace lumar::gl {
namespace {

std::string glfw_error_text() {
  const char* description = nullptr;
  const int code = glfwGetError(&description);
  return code == GLFW_NO_ERROR ? std::string("no GLFW error reported")
                               : std::string(description ? description : "unknown GLFW error");
}

// GLFW is initialised on first use and kept for the life of the process, as the EGL
// display is: glfwTerminate would unload the GL driver under anything still using it.
void initialise_glfw() {
  static std::mutex mutex;
  static bool initialised = false;
  std::lock_guard lock(mutex);
  if (initialised) return;
  if (!glfwInit())
    throw RuntimeError("OpenGL window: cannot open the display (" + glfw_error_text() +
                       "); run under X11 with DISPLAY set, or use the headless mode");
  initialised = true;
}

}  // namespace

struct WindowContext::Impl {
  GLFWwindow* window = nullptr;
  std::string name;
  GlName image;      // the last presented image, as a texture
  GlName image_fbo;  // reads `image` for the blit
  int image_width = 0, image_height = 0;
};

WindowContext::WindowContext(int width, int height, const std::string& title) : impl_(std::make_unique<Impl>()) {
  if (width <= 0 || height <= 0)
    throw InputError("OpenGL window: size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is not positive; give a real window size");
  initialise_glfw();
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_TRUE);
  impl_->window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!impl_->window) {
    throw RuntimeError("OpenGL window: cannot create a " + std::to_string(width) + "x" + std::to_string(height) +
                       " window with OpenGL 4.5 core (" + glfw_error_text() + "); check the display's GL driver");
  }
  glfwMakeContextCurrent(impl_->window);
  glfwSwapInterval(1);  // no tearing; the display pace is the camera's anyway
  impl_->name = std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))) + ", OpenGL " +
                reinterpret_cast<const char*>(glGetString(GL_VERSION));
  impl_->image_fbo = create_framebuffer();
}

WindowContext::~WindowContext() {
  // GL names die with the context, but delete them while it is current to be tidy.
  glfwMakeContextCurrent(impl_->window);
  impl_->image.reset();
  impl_->image_fbo.reset();
  glfwMakeContextCurrent(nullptr);
  glfwDestroyWindow(impl_->window);
}

void WindowContext::make_current() { glfwMakeContextCurrent(impl_->window); }

std::string WindowContext::renderer_name() const { return impl_->name; }

bool WindowContext::should_close() const { return glfwWindowShouldClose(impl_->window); }

void WindowContext::poll_events() { glfwPollEvents(); }

void WindowContext::wait_events(double seconds) { glfwWaitEventsTimeout(seconds); }

GLFWwindow* WindowContext::window_handle() { return impl_->window; }

void WindowContext::present_in_corner(const cv::Mat& bgr8, const std::function<void()>& draw_over) {
  if (bgr8.type() != CV_8UC3 || bgr8.empty())
    throw InputError("OpenGL window: present_in_corner needs a non-empty BGR8 (CV_8UC3) image");
  make_current();
  Impl& w = *impl_;
  if (bgr8.cols != w.image_width || bgr8.rows != w.image_height) {
    w.image = create_texture_2d(GL_RGB8, bgr8.cols, bgr8.rows, GL_LINEAR, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
    glNamedFramebufferTexture(w.image_fbo.get(), GL_COLOR_ATTACHMENT0, w.image.get(), 0);
    glNamedFramebufferReadBuffer(w.image_fbo.get(), GL_COLOR_ATTACHMENT0);
    check_framebuffer(w.image_fbo.get(), "the window's image");
    w.image_width = bgr8.cols;
    w.image_height = bgr8.rows;
  }
  upload_bgr8(w.image.get(), bgr8);  // texel row 0 = the image's top row

  int fb_width = 0, fb_height = 0;
  glfwGetFramebufferSize(w.window, &fb_width, &fb_height);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glDrawBuffer(GL_BACK);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_FRAMEBUFFER_SRGB);
  glViewport(0, 0, fb_width, fb_height);
  glClearColor(0.12f, 0.12f, 0.13f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  // Texel row 0 (the top row) goes to the window's top edge: flip the destination.
  glBlitNamedFramebuffer(w.image_fbo.get(), 0, 0, 0, bgr8.cols, bgr8.rows, 0, fb_height, bgr8.cols,
                         fb_height - bgr8.rows, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  check_gl_errors("WindowContext::present_in_corner");
  if (draw_over) draw_over();
  check_gl_errors("WindowContext::present_in_corner, drawing over");
  glfwSwapBuffers(w.window);
}

cv::Mat WindowContext::read_back_buffer() {
  make_current();
  int width = 0, height = 0;
  glfwGetFramebufferSize(impl_->window, &width, &height);
  cv::Mat image(height, width, CV_8UC3);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glReadPixels(0, 0, width, height, GL_BGR, GL_UNSIGNED_BYTE, image.data);
  check_gl_errors("WindowContext::read_back_buffer");
  cv::flip(image, image, 0);  // GL's rows start at the bottom
  return image;
}

cv::Mat WindowContext::read_front_buffer() {
  // Mesa's software GLX keeps no readable front buffer (GL_FRONT reads zeros), so ask
  // the X server for what it shows instead: the truer answer anyway.
  make_current();
  glFinish();
  return read_x11_window_image(impl_->window);
}

}  // namespace lumar::gl
