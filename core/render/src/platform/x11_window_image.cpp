#include "platform/x11_window_image.h"

#include <string>

#include "lumar/base/error.h"

// Xlib last: its macros must not reach the headers above.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>

// From GLFW's X11 native interface (glfw3native.h, which would also need the XRandR
// headers that this program does not use).
extern "C" {
Display* glfwGetX11Display(void);
Window glfwGetX11Window(GLFWwindow* window);
}

namespace lumar::gl {
namespace {

// Scales a masked channel of an X pixel to 8 bits.
unsigned char channel(unsigned long pixel, unsigned long mask) {
  if (mask == 0) return 0;
  int shift = 0;
  while (!((mask >> shift) & 1)) ++shift;
  const unsigned long max = mask >> shift;
  return static_cast<unsigned char>(((pixel & mask) >> shift) * 255 / max);
}

}  // namespace

cv::Mat read_x11_window_image(GLFWwindow* window) {
  Display* display = glfwGetX11Display();
  const Window x_window = glfwGetX11Window(window);
  if (!display || !x_window)
    throw RuntimeError("OpenGL window: not an X11 window, cannot read what it shows; run under X11");
  XWindowAttributes attributes{};
  XGetWindowAttributes(display, x_window, &attributes);
  XImage* image =
      XGetImage(display, x_window, 0, 0, unsigned(attributes.width), unsigned(attributes.height), AllPlanes, ZPixmap);
  if (!image) throw RuntimeError("OpenGL window: XGetImage failed (is the window mapped and on screen?)");
  cv::Mat out(attributes.height, attributes.width, CV_8UC3);
  for (int r = 0; r < out.rows; ++r)
    for (int c = 0; c < out.cols; ++c) {
      const unsigned long p = XGetPixel(image, c, r);
      out.at<cv::Vec3b>(r, c) = {channel(p, image->blue_mask), channel(p, image->green_mask),
                                 channel(p, image->red_mask)};
    }
  XDestroyImage(image);
  return out;
}

}  // namespace lumar::gl
