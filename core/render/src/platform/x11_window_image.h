#pragma once
// What the X server shows in a GLFW window. Kept apart because Xlib's macros (None,
// Status, Bool) clash with other headers.
#include <opencv2/core.hpp>

struct GLFWwindow;

namespace lumar::gl {

// The window's pixels as the X server has them (XGetImage), BGR8, top row first.
// Throws RuntimeError when the window is not an X11 window or cannot be read.
cv::Mat read_x11_window_image(GLFWwindow* window);

}  // namespace lumar::gl
