#pragma once
// Small helpers around raw OpenGL 4.5 (direct state access): owning names, shader
// programs, error checks. Private to core/render.
#include <epoxy/gl.h>

#include <opencv2/core.hpp>
#include <string>
#include <utility>

namespace lumar::gl {

// An owned OpenGL object name; deleted (with the function it was made with) when this
// goes away, so the context that made it must be current then.
class GlName {
 public:
  using Deleter = void (*)(GLuint);
  GlName() = default;
  GlName(GLuint id, Deleter deleter) : id_(id), deleter_(deleter) {}
  GlName(GlName&& o) noexcept : id_(std::exchange(o.id_, 0)), deleter_(o.deleter_) {}
  GlName& operator=(GlName&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
      deleter_ = o.deleter_;
    }
    return *this;
  }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;
  ~GlName() { reset(); }

  GLuint get() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_ && deleter_) deleter_(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
  Deleter deleter_ = nullptr;
};

GlName create_texture_2d(GLenum internal_format, int width, int height, GLenum filter, GLenum wrap_s, GLenum wrap_t);
// `flags`: glNamedBufferStorage's (GL_DYNAMIC_STORAGE_BIT: updatable with glNamedBufferSubData).
GlName create_buffer(const void* data, std::size_t bytes, GLbitfield flags = 0);
GlName create_framebuffer();
GlName create_vertex_array();
// Feeds vertex attribute `attribute` of `vertex_array` from a tightly packed buffer of
// `components` floats per vertex (binding point = attribute index).
void attach_float_attribute(GLuint vertex_array, GLuint attribute, GLuint buffer, int components);

// Compiles and links a program; throws RuntimeError naming `name` with the driver's
// log (on one line) when compiling or linking fails.
GlName create_program(const char* name, const char* vertex_source, const char* fragment_source);
// `source` with the GLSL functions of `library` (no #version line of its own) inserted
// after its #version line, so that its code may use them.
std::string with_glsl_library(const char* source, const char* library);

// True when an EGL or GLX context is current on this thread (GL calls without one abort).
bool any_context_current();

// Throws RuntimeError naming `where` if OpenGL recorded an error since the last check.
void check_gl_errors(const char* where);
// Throws RuntimeError naming `where` unless the framebuffer is complete.
void check_framebuffer(GLuint framebuffer, const char* where);

// Uploads a BGR8 image (continuous or a strided ROI) into a GL_RGB8 texture of the same
// size, rows as they are: texel row 0 is the image's top row (GL would call it the
// bottom; the shaders account for that).
void upload_bgr8(GLuint texture, const cv::Mat& bgr8);

}  // namespace lumar::gl
