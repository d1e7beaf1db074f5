// Kept apart: epoxy/glx.h pulls in Xlib, whose macros (None, Status, Bool) clash with other headers.
#include <epoxy/egl.h>
#include <epoxy/glx.h>

namespace lumar::gl {

bool any_context_current() { return eglGetCurrentContext() != EGL_NO_CONTEXT || glXGetCurrentContext() != nullptr; }

}  // namespace lumar::gl
