// The surfaceless EGL context: OpenGL 4.5 core with no display server at all.
#include <epoxy/gl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "lumar/render/platform/context.h"

namespace {

struct GlVersion {
  int major = 0, minor = 0, profile = 0;
};

GlVersion current_version() {
  GlVersion v;
  glGetIntegerv(GL_MAJOR_VERSION, &v.major);
  glGetIntegerv(GL_MINOR_VERSION, &v.minor);
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &v.profile);
  return v;
}

TEST(RenderHeadless, OpenGL45CoreWithDisplayUnset) {
  unsetenv("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  auto context = lumar::gl::create_headless_context();
  const GlVersion v = current_version();
  std::printf("headless renderer: %s\n", context->renderer_name().c_str());
  EXPECT_GE(v.major * 10 + v.minor, 45);
  EXPECT_TRUE(v.profile & GL_CONTEXT_CORE_PROFILE_BIT);
  EXPECT_THAT(context->renderer_name(), testing::HasSubstr("OpenGL 4."));
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

TEST(RenderHeadless, ContextsShareTheDisplaySafely) {
  // Destroying one context must not end another's display (eglTerminate is not counted).
  auto a = lumar::gl::create_headless_context();
  auto b = lumar::gl::create_headless_context();
  a.reset();
  b->make_current();
  GLuint fbo = 0, tex = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &tex);
  glTextureStorage2D(tex, 1, GL_RGBA8, 4, 4);
  glCreateFramebuffers(1, &fbo);
  glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, tex, 0);
  const float colour[4] = {0.25f, 0.5f, 1.0f, 1.0f};
  glClearNamedFramebufferfv(fbo, GL_COLOR, 0, colour);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  unsigned char px[4] = {};
  glReadPixels(1, 1, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
  EXPECT_NEAR(px[0], 64, 1);
  EXPECT_NEAR(px[1], 128, 1);
  EXPECT_EQ(px[2], 255);
  glDeleteFramebuffers(1, &fbo);
  glDeleteTextures(1, &tex);
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

}  // namespace
