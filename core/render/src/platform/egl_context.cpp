// Headless OpenGL: EGL on Mesa's surfaceless platform. No window system is involved,
// so it works on servers, in CI and with DISPLAY unset; drawing goes to FBOs.
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstring>
#include <mutex>
#include <string>

#include "gl_util.h"
#include "lumar/base/error.h"
#include "lumar/render/platform/context.h"

namespace lumar::gl {
namespace {

bool has_token(const char* list, const char* token) { return list && epoxy_extension_in_string(list, token); }

std::string egl_error_text() { return cv::format("EGL error 0x%04x", eglGetError()); }

// The surfaceless display, initialised on first use and kept for the life of the
// process: eglTerminate would end every context on it and unload the driver, and one
// idle display costs nothing.
EGLDisplay surfaceless_display() {
  static std::mutex mutex;
  static EGLDisplay display = EGL_NO_DISPLAY;
  std::lock_guard lock(mutex);
  if (display != EGL_NO_DISPLAY) return display;
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!has_token(client, "EGL_MESA_platform_surfaceless") || !has_token(client, "EGL_EXT_platform_base"))
    throw RuntimeError(
        "OpenGL: EGL has no surfaceless platform (EGL_MESA_platform_surfaceless); install Mesa's EGL "
        "(libegl-mesa0) for headless rendering");
  EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (d == EGL_NO_DISPLAY || !eglInitialize(d, nullptr, nullptr))
    throw RuntimeError("OpenGL: cannot initialise the EGL surfaceless display (" + egl_error_text() +
                       "); check the Mesa installation");
  display = d;
  return display;
}

class HeadlessContext : public Context {
 public:
  HeadlessContext() : display_(surfaceless_display()) {
    try {
      create();
    } catch (...) {
      destroy();
      throw;
    }
  }
  ~HeadlessContext() override { destroy(); }

  void make_current() override {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw RuntimeError("OpenGL: cannot make the headless EGL context current (" + egl_error_text() +
                         "); is it current on another thread?");
  }
  std::string renderer_name() const override { return name_; }

 private:
  void create() {
    if (!eglBindAPI(EGL_OPENGL_API))
      throw RuntimeError("OpenGL: EGL cannot bind the desktop OpenGL API (" + egl_error_text() +
                         "); install Mesa's OpenGL driver");
    const char* extensions = eglQueryString(display_, EGL_EXTENSIONS);
    if (!has_token(extensions, "EGL_KHR_surfaceless_context"))
      throw RuntimeError("OpenGL: the EGL display lacks EGL_KHR_surfaceless_context; update Mesa");
    // Surfaceless displays offer pbuffer configs only, so ask for those, not windows.
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                        EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!eglChooseConfig(display_, config_attributes, &config, 1, &count) || count < 1)
      throw RuntimeError("OpenGL: EGL offers no desktop-OpenGL config on the surfaceless display (" + egl_error_text() +
                         "); install Mesa's OpenGL driver");
    const EGLint context_attributes[] = {
        EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, context_attributes);
    if (context_ == EGL_NO_CONTEXT)
      throw RuntimeError("OpenGL: cannot create an OpenGL 4.5 core context with EGL (" + egl_error_text() +
                         "); the driver needs OpenGL 4.5 (Mesa llvmpipe 20 or newer has it)");
    make_current();
    if (epoxy_gl_version() < 45)
      throw RuntimeError("OpenGL: the headless context is OpenGL " + std::to_string(epoxy_gl_version()) +
                         ", 4.5 is needed; update Mesa");
    name_ = std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))) + ", OpenGL " +
            reinterpret_cast<const char*>(glGetString(GL_VERSION));
  }

  void destroy() {
    if (context_ != EGL_NO_CONTEXT) {
      if (eglGetCurrentContext() == context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display_, context_);
      context_ = EGL_NO_CONTEXT;
    }
  }

  const EGLDisplay display_;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string name_;
};

}  // namespace

std::unique_ptr<Context> create_headless_context() { return std::make_unique<HeadlessContext>(); }

void load_headless_driver() {
  try {
    surfaceless_display();
  } catch (const RuntimeError&) {
  }
}

}  // namespace lumar::gl
