#include "gl_util.h"

#include <string>

#include "lumar/base/error.h"

namespace lumar::gl {
namespace {

void delete_texture(GLuint id) { glDeleteTextures(1, &id); }
void delete_buffer(GLuint id) { glDeleteBuffers(1, &id); }
void delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
void delete_program(GLuint id) { glDeleteProgram(id); }
void delete_shader(GLuint id) { glDeleteShader(id); }

// Driver logs span lines; errors reaching the user are one line.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

GlName compile_shader(const char* program_name, GLenum stage, const char* source) {
  GlName shader(glCreateShader(stage), delete_shader);
  glShaderSource(shader.get(), 1, &source, nullptr);
  glCompileShader(shader.get());
  GLint ok = GL_FALSE;
  glGetShaderiv(shader.get(), GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(shader.get(), GL_INFO_LOG_LENGTH, &length);
    std::string log(std::max(length, 1), '\0');
    glGetShaderInfoLog(shader.get(), length, nullptr, log.data());
    throw RuntimeError(std::string("OpenGL: the ") + program_name +
                       (stage == GL_VERTEX_SHADER ? " vertex" : " fragment") +
                       " shader does not compile on this driver: " + one_line(log.c_str()) +
                       " (a bug in lumar; report it with the GL renderer name)");
  }
  return shader;
}

const char* error_name(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    case GL_STACK_OVERFLOW:
      return "GL_STACK_OVERFLOW";
    case GL_STACK_UNDERFLOW:
      return "GL_STACK_UNDERFLOW";
    default:
      return "unknown GL error";
  }
}

}  // namespace

GlName create_texture_2d(GLenum internal_format, int width, int height, GLenum filter, GLenum wrap_s, GLenum wrap_t) {
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  GlName texture(id, delete_texture);
  glTextureStorage2D(id, 1, internal_format, width, height);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, filter);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, filter);
  glTextureParameteri(id, GL_TEXTURE_WRAP_S, wrap_s);
  glTextureParameteri(id, GL_TEXTURE_WRAP_T, wrap_t);
  const float black[4] = {0, 0, 0, 0};
  glTextureParameterfv(id, GL_TEXTURE_BORDER_COLOR, black);
  return texture;
}

GlName create_buffer(const void* data, std::size_t bytes, GLbitfield flags) {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  GlName buffer(id, delete_buffer);
  glNamedBufferStorage(id, GLsizeiptr(bytes), data, flags);
  return buffer;
}

void attach_float_attribute(GLuint vertex_array, GLuint attribute, GLuint buffer, int components) {
  glVertexArrayVertexBuffer(vertex_array, attribute, buffer, 0, GLsizei(sizeof(float)) * components);
  glVertexArrayAttribFormat(vertex_array, attribute, components, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(vertex_array, attribute, attribute);
  glEnableVertexArrayAttrib(vertex_array, attribute);
}

GlName create_framebuffer() {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  return GlName(id, delete_framebuffer);
}

GlName create_vertex_array() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  return GlName(id, delete_vertex_array);
}

std::string with_glsl_library(const char* source, const char* library) {
  std::string s(source);
  const std::size_t version = s.find("#version");
  const std::size_t line_end = version == std::string::npos ? std::string::npos : s.find('\n', version);
  if (line_end == std::string::npos) throw RuntimeError("OpenGL: a shader has no #version line (a bug in lumar)");
  return s.insert(line_end + 1, library);
}

GlName create_program(const char* name, const char* vertex_source, const char* fragment_source) {
  GlName vs = compile_shader(name, GL_VERTEX_SHADER, vertex_source);
  GlName fs = compile_shader(name, GL_FRAGMENT_SHADER, fragment_source);
  GlName program(glCreateProgram(), delete_program);
  glAttachShader(program.get(), vs.get());
  glAttachShader(program.get(), fs.get());
  glLinkProgram(program.get());
  glDetachShader(program.get(), vs.get());
  glDetachShader(program.get(), fs.get());
  GLint ok = GL_FALSE;
  glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(program.get(), GL_INFO_LOG_LENGTH, &length);
    std::string log(std::max(length, 1), '\0');
    glGetProgramInfoLog(program.get(), length, nullptr, log.data());
    throw RuntimeError(std::string("OpenGL: the ") + name + " program does not link: " + one_line(log.c_str()) +
                       " (a bug in lumar; report it with the GL renderer name)");
  }
  return program;
}

void check_gl_errors(const char* where) {
  const GLenum first = glGetError();
  if (first == GL_NO_ERROR) return;
  while (glGetError() != GL_NO_ERROR) {
  }
  throw RuntimeError(std::string("OpenGL: ") + error_name(first) + " in " + where +
                     " (a bug in lumar or a driver limit; report it with the GL renderer name)");
}

void check_framebuffer(GLuint framebuffer, const char* where) {
  const GLenum status = glCheckNamedFramebufferStatus(framebuffer, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw RuntimeError(std::string("OpenGL: framebuffer for ") + where + " is incomplete (status 0x" +
                       cv::format("%04x", status) + "); the driver lacks a needed format");
}

void upload_bgr8(GLuint texture, const cv::Mat& bgr8) {
  // Rows may be padded (a ROI); tell GL the row length when it is a whole number of pixels.
  cv::Mat src = bgr8;
  if (src.step[0] % 3 != 0) src = bgr8.clone();
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, GLint(src.step[0] / 3));
  glTextureSubImage2D(texture, 0, 0, 0, src.cols, src.rows, GL_BGR, GL_UNSIGNED_BYTE, src.data);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
}

}  // namespace lumar::gl
