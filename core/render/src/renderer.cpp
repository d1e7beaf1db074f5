#include "lumar/render/renderer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "gl_util.h"
#include "gpu_mesh.h"
#include "irradiance_textures.h"
#include "lumar/base/error.h"
#include "shaders.h"
#include "shadow_pass.h"

namespace lumar::gl {
namespace {

// An offscreen framebuffer: one colour texture, optionally a 32-bit float depth texture.
struct RenderTarget {
  int width = 0, height = 0;
  GlName framebuffer, color, depth;

  RenderTarget() = default;
  RenderTarget(int w, int h, GLenum color_format, bool with_depth, const char* what) : width(w), height(h) {
    framebuffer = create_framebuffer();
    color = create_texture_2d(color_format, w, h, GL_NEAREST, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
    glNamedFramebufferTexture(framebuffer.get(), GL_COLOR_ATTACHMENT0, color.get(), 0);
    if (with_depth) {
      depth = create_texture_2d(GL_DEPTH_COMPONENT32F, w, h, GL_NEAREST, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
      glNamedFramebufferTexture(framebuffer.get(), GL_DEPTH_ATTACHMENT, depth.get(), 0);
    }
    glNamedFramebufferDrawBuffer(framebuffer.get(), GL_COLOR_ATTACHMENT0);
    glNamedFramebufferReadBuffer(framebuffer.get(), GL_COLOR_ATTACHMENT0);
    check_framebuffer(framebuffer.get(), what);
  }

  // Binds for drawing, sets the viewport, clears colour to zero and depth to far.
  void begin() const {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
    glViewport(0, 0, width, height);
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(framebuffer.get(), GL_COLOR, 0, zero);
    if (depth) {
      const float far = 1.0f;
      glClearNamedFramebufferfv(framebuffer.get(), GL_DEPTH, 0, &far);
    }
  }
};

// A multisampled offscreen framebuffer: colour and 32-bit float depth, `samples` each.
struct MultisampleTarget {
  int width = 0, height = 0, samples = 0;
  GlName framebuffer, color, depth;

  MultisampleTarget() = default;
  MultisampleTarget(int w, int h, int n, GLenum color_format) : width(w), height(h), samples(n) {
    framebuffer = create_framebuffer();
    const auto texture = [&](GLenum format) {
      GLuint id = 0;
      glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &id);
      glTextureStorage2DMultisample(id, n, format, w, h, GL_TRUE);
      return GlName(id, [](GLuint t) { glDeleteTextures(1, &t); });
    };
    color = texture(color_format);
    depth = texture(GL_DEPTH_COMPONENT32F);
    glNamedFramebufferTexture(framebuffer.get(), GL_COLOR_ATTACHMENT0, color.get(), 0);
    glNamedFramebufferTexture(framebuffer.get(), GL_DEPTH_ATTACHMENT, depth.get(), 0);
    glNamedFramebufferDrawBuffer(framebuffer.get(), GL_COLOR_ATTACHMENT0);
    check_framebuffer(framebuffer.get(), "the multisampled scene");
  }

  void begin() const {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
    glViewport(0, 0, width, height);
    const float zero[4] = {0, 0, 0, 0}, far = 1.0f;
    glClearNamedFramebufferfv(framebuffer.get(), GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(framebuffer.get(), GL_DEPTH, 0, &far);
  }
};

GLint uniform(GLuint program, const char* name) { return glGetUniformLocation(program, name); }

constexpr int kMaxBlurRadius = 12;  // pixels: the camera's blur is at most sigma 4

// Wall-clock stage timer; waits for the GPU at each mark so the stages are separable.
class StageClock {
 public:
  explicit StageClock(bool enabled) : enabled_(enabled), last_(now()) {}
  void mark(double* ms) {
    if (!enabled_) return;
    glFinish();
    const auto t = now();
    *ms = std::chrono::duration<double, std::milli>(t - last_).count();
    last_ = t;
  }

 private:
  static std::chrono::steady_clock::time_point now() { return std::chrono::steady_clock::now(); }
  bool enabled_;
  std::chrono::steady_clock::time_point last_;
};

// The bound framebuffer as floats, top row first (GL rows run bottom-up).
cv::Mat read_float_pixels(int width, int height, GLenum format, int cv_type, const char* what) {
  cv::Mat out(height, width, cv_type);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glReadPixels(0, 0, width, height, format, GL_FLOAT, out.data);
  check_gl_errors(what);
  cv::flip(out, out, 0);
  return out;
}

}  // namespace

struct Renderer::Impl {
  struct Object {
    GpuMesh mesh;
    glm::mat4 model{1.0f};
    glm::mat3 normal_matrix{1.0f};
    glm::vec3 albedo{0.8f};
    std::array<glm::vec3, 9> sh{};
    glm::vec3 lo{0.0f}, hi{0.0f};  // model-space bounds
    bool vertex_lit = false;       // shaded by its per-vertex irradiance (set_object_vertex_irradiance)
    int level = 0;                 // of its simplified meshes, for this frame's coverage (choose_levels)
    void set_pose(const glm::dmat4& T_world_model) {
      model = glm::mat4(T_world_model);
      normal_matrix = glm::mat3(glm::transpose(glm::inverse(glm::dmat3(T_world_model))));
    }
  };

  // Each object's coarsest mesh level within coverage_error_px of its mesh, where the
  // object is nearest the camera: an error e (model units) at distance d (model units; a
  // uniform scale cancels) spans at most e * f / d pixels.
  void choose_levels(const Pose& T_world_camera) {
    const float f = float(std::max(camera.fx, camera.fy));
    for (Object& o : objects) {
      o.level = 0;
      if (coverage_error_px <= 0.0f) continue;
      const glm::vec3 eye = glm::vec3(glm::inverse(o.model) * glm::vec4(glm::vec3(T_world_camera.translation), 1.0f));
      const float d = glm::length(eye - glm::clamp(eye, o.lo, o.hi));
      if (d > 0.0f) o.level = o.mesh.level_within(coverage_error_px * d / f);
    }
  }

  // The pixels the objects may cover (their boxes projected, 2 px more), clipped to the
  // image; the whole image when a box reaches behind the camera.
  // `which`: only the objects it marks (nullptr: all).
  cv::Rect objects_footprint(const glm::mat4& vp, const std::vector<char>* which = nullptr) const {
    const cv::Rect image(0, 0, camera.width, camera.height);
    float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      if (which && !(*which)[i]) continue;
      const Object& o = objects[i];
      for (int k = 0; k < 8; ++k) {
        const glm::vec3 corner((k & 1) ? o.hi.x : o.lo.x, (k & 2) ? o.hi.y : o.lo.y, (k & 4) ? o.hi.z : o.lo.z);
        const glm::vec4 clip = vp * o.model * glm::vec4(corner, 1.0f);
        if (clip.w <= 1e-6f) return image;
        const float x = (clip.x / clip.w * 0.5f + 0.5f) * float(camera.width);
        const float y = (clip.y / clip.w * 0.5f + 0.5f) * float(camera.height);  // GL rows, bottom up
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
    }
    if (x1 < x0) return {};
    const cv::Rect box(cv::Point(int(std::floor(x0)) - 2, int(std::floor(y0)) - 2),
                       cv::Point(int(std::ceil(x1)) + 3, int(std::ceil(y1)) + 3));
    return box & image;
  }

  CameraIntrinsics camera;
  GlName empty_vertex_array;  // core profile needs one bound even for attribute-less draws
  GlName background, depth_only, shaded_object, world_position, room_radiance, encode, blur, resample, covered,
      antialias_resolve, weighted_copy;
  GpuMesh room;
  std::unique_ptr<ShadowPass> receivers;  // shadow receivers, drawn over the video
  std::unique_ptr<ShadowPass> contact;    // dense receivers where objects touch them, drawn after
  std::vector<Object> objects;

  GlName video;
  int video_width = 0, video_height = 0;
  GlName undistortion_map;

  GlName response_decode, response_encode;  // empty: sRGB
  glm::vec3 response_max{1.0f};
  glm::vec2 vignetting{0.0f};
  CameraIntrinsics video_camera;                               // the distorted camera the vignetting is defined on
  glm::vec3 noise_read_variance{0.0f}, noise_shot_gain{0.0f};  // RGB
  float blur_sigma = 0.0f;
  glm::ivec2 chroma_block{1, 1};  // pixels per chroma sample (VideoRadiometry's)
  CompositeFeatures features;
  float coverage_error_px = 0.0f;
  std::uint32_t frame_number = 0;  // seeds the noise: a new draw every frame

  std::unique_ptr<IrradianceTextures> volume;  // shades objects when set
  GlName environment;
  glm::vec3 capture_position{0.0f};
  glm::mat3 map_from_world{1.0f};

  RenderTarget scene;                  // linear colour (RGBA32F) and depth, output size
  MultisampleTarget multisampled;      // the objects' coverage, 4 samples per pixel
  RenderTarget coverage;               // its resolve (R8)
  RenderTarget scratch, scratch_rows;  // a copy of part of `scene`, the blur's rows (RGBA32F)
  RenderTarget still, accumulated;     // motion blur: the background kept, the instants' sum (RGBA32F)
  RenderTarget encoded;                // sRGB 8-bit, output size, rows flipped for read-back
  RenderTarget encoded_copy;           // part of `encoded`, for the resample pass to read
  RenderTarget room_target;            // for render_room_radiance, resized on demand

  Object& object(int id, const char* where) {
    if (id < 0 || id >= int(objects.size()))
      throw InputError(std::string("Renderer::") + where + ": no object with id " + std::to_string(id) +
                       "; use an id returned by add_object");
    return objects[std::size_t(id)];
  }

  static glm::mat4 view_projection(const CameraIntrinsics& c, const Pose& T_world_camera) {
    return glm::mat4(opengl_projection(c, kNear, kFar) * opengl_view(T_world_camera));
  }

  static void set_transform(GLuint program, const glm::mat4& model, const glm::mat3& normal_matrix,
                            const glm::mat4& vp) {
    glProgramUniformMatrix4fv(program, uniform(program, "model"), 1, GL_FALSE, glm::value_ptr(model));
    glProgramUniformMatrix3fv(program, uniform(program, "normal_matrix"), 1, GL_FALSE, glm::value_ptr(normal_matrix));
    glProgramUniformMatrix4fv(program, uniform(program, "view_projection"), 1, GL_FALSE, glm::value_ptr(vp));
  }

  // The proxy room into depth only: real surfaces hide virtual objects behind them.
  void draw_room_depth(const glm::mat4& vp) {
    if (room.empty()) return;
    glUseProgram(depth_only.get());
    set_transform(depth_only.get(), glm::mat4(1.0f), glm::mat3(1.0f), vp);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    room.draw();
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  }

  // outline_only: what is drawn is only where the objects are, not how they look (their
  // coverage), so each may be its simplified mesh of this frame (choose_levels).
  void draw_objects(GLuint program, const glm::mat4& vp, bool shaded, float exposure, bool outline_only = false) {
    glUseProgram(program);
    if (shaded) glProgramUniform1f(program, uniform(program, "exposure"), exposure);
    if (shaded) glProgramUniform1i(program, uniform(program, "use_volume"), volume ? 1 : 0);
    if (shaded) glProgramUniform1i(program, uniform(program, "use_self_occlusion"), features.self_occlusion ? 1 : 0);
    if (shaded && volume) volume->bind(program);
    for (const Object& o : objects) {
      set_transform(program, o.model, o.normal_matrix, vp);
      if (shaded) {
        glProgramUniform3fv(program, uniform(program, "albedo"), 1, glm::value_ptr(o.albedo));
        glProgramUniform3fv(program, uniform(program, "sh"), 9, glm::value_ptr(o.sh[0]));
        glProgramUniform1i(program, uniform(program, "use_vertex_irradiance"), o.vertex_lit ? 1 : 0);
      }
      o.mesh.draw(outline_only ? o.level : 0);
    }
  }

  void draw_fullscreen() {
    glBindVertexArray(empty_vertex_array.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }

  void upload_video(const cv::Mat& frame) {
    if (frame.cols != video_width || frame.rows != video_height) {
      // Read by texel (the background pass filters in linear light), never filtered as codes.
      video = create_texture_2d(GL_RGB8, frame.cols, frame.rows, GL_NEAREST, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
      video_width = frame.cols;
      video_height = frame.rows;
    }
    upload_bgr8(video.get(), frame);
  }

  // The pixels within `rect` (GL rows, bottom up) of one framebuffer copied to the same
  // place in another (a multisampled source is resolved). Copying part of `scene` lets a
  // pass that reads its neighbours write into `scene` itself, touching only the pixels it
  // changes, not the whole image.
  static void copy_within(GLuint from, const RenderTarget& to, const cv::Rect& rect) {
    glBlitNamedFramebuffer(from, to.framebuffer.get(), rect.x, rect.y, rect.x + rect.width, rect.y + rect.height,
                           rect.x, rect.y, rect.x + rect.width, rect.y + rect.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }

  // Binds `target` for a pass limited to `rect` (scissored; nothing cleared).
  void begin_within(const RenderTarget& target, const cv::Rect& rect) const {
    glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer.get());
    glViewport(0, 0, target.width, target.height);
    glEnable(GL_SCISSOR_TEST);
    glScissor(rect.x, rect.y, rect.width, rect.height);
  }

  void make_scratch() {
    if (scratch.width == camera.width && scratch.height == camera.height) return;
    scratch = RenderTarget(camera.width, camera.height, GL_RGBA32F, false, "the scene's copy");
    scratch_rows = RenderTarget(camera.width, camera.height, GL_RGBA32F, false, "the blur's rows");
  }

  // Antialiasing of `scene`, in place, at the cost of one shaded sample per pixel: the
  // objects' coverage of each pixel from a multisampled pass that only rasterises (the
  // proxy's depth, then the objects with a constant colour), then each outline pixel
  // mixes the object's and the video's colours by that coverage, the kind its centre
  // missed taken from its 3x3 neighbours. Shading every sample instead costs llvmpipe five
  // times the objects' time. Only within the objects' footprint `box`: multisampled passes
  // and whole-image copies are dear on a software rasteriser.
  void antialias(const glm::mat4& vp, const cv::Rect& box, const Pose& T_world_camera) {
    if (box.empty()) return;
    make_scratch();
    if (coverage.width != camera.width || coverage.height != camera.height)
      coverage = RenderTarget(camera.width, camera.height, GL_R8, false, "the objects' coverage");
    glEnable(GL_SCISSOR_TEST);
    glScissor(box.x, box.y, box.width, box.height);
    multisampled.begin();  // clears within the scissor only
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    draw_room_depth(vp);
    choose_levels(T_world_camera);
    draw_objects(covered.get(), vp, false, 0.0f, true);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_SCISSOR_TEST);
    copy_within(multisampled.framebuffer.get(), coverage, box);
    // The resolve reads each pixel's 3x3 neighbours.
    copy_within(scene.framebuffer.get(), scratch, grown(box, 1));
    begin_within(scene, box);
    glUseProgram(antialias_resolve.get());
    glBindTextureUnit(shaders::kLinearImageUnit, scratch.color.get());
    glBindTextureUnit(shaders::kCoverageUnit, coverage.color.get());
    draw_fullscreen();
    glDisable(GL_SCISSOR_TEST);
  }

  // `rect` grown by `margin` pixels each way, clipped to the image.
  cv::Rect grown(const cv::Rect& rect, int margin) const {
    return cv::Rect(rect.x - margin, rect.y - margin, rect.width + 2 * margin, rect.height + 2 * margin) &
           cv::Rect(0, 0, camera.width, camera.height);
  }

  int blur_radius() const { return std::min(int(std::ceil(3.0f * blur_sigma)), kMaxBlurRadius); }

  // The camera's blur on what was rendered, in `scene` in place: a separable Gaussian
  // (rows, then columns), kept only where it reaches a rendered pixel (alpha > 0); the
  // video elsewhere has the camera's blur already. Rendered pixels lie within the objects'
  // footprint `box`, so only that box grown by the kernel's radius can change.
  void blur_rendered(const cv::Rect& box) {
    if (box.empty()) return;
    make_scratch();
    const int radius = blur_radius();
    const cv::Rect changed = grown(box, radius), read = grown(box, 2 * radius);
    copy_within(scene.framebuffer.get(), scratch, read);
    const GLuint p = blur.get();
    glUseProgram(p);
    glProgramUniform1f(p, uniform(p, "sigma"), blur_sigma);
    glProgramUniform1i(p, uniform(p, "radius"), radius);
    glBindTextureUnit(shaders::kLinearImageUnit, scratch.color.get());
    glBindTextureUnit(shaders::kBlurSourceUnit, scratch.color.get());
    // The rows wherever the columns will read them: the changed columns, the rows a radius beyond.
    begin_within(scratch_rows, cv::Rect(changed.x, read.y, changed.width, read.height));
    glProgramUniform2i(p, uniform(p, "step"), 1, 0);
    draw_fullscreen();
    begin_within(scene, changed);
    glBindTextureUnit(shaders::kBlurSourceUnit, scratch_rows.color.get());
    glProgramUniform2i(p, uniform(p, "step"), 0, 1);
    draw_fullscreen();
    glDisable(GL_SCISSOR_TEST);
  }

  // Rendered pixels (scene alpha > 0) within `box` (GL rows of `scene`), in `encoded`:
  // resampled as the undistortion (there must be a map) resampled the video, after the
  // encode pass's clipping, and their light spread into the video pixels beside them.
  void resample_rendered(const cv::Rect& box) {
    if (box.empty()) return;
    if (encoded_copy.width != camera.width || encoded_copy.height != camera.height)
      encoded_copy = RenderTarget(camera.width, camera.height, GL_RGBA8, false, "the encoded output's copy");
    const cv::Rect changed = grown(cv::Rect(box.x, camera.height - box.y - box.height, box.width, box.height), 1);
    copy_within(encoded.framebuffer.get(), encoded_copy, grown(changed, 1));
    begin_within(encoded, changed);
    const GLuint p = resample.get();
    glUseProgram(p);
    glProgramUniform1i(p, uniform(p, "use_response_lut"), response_encode ? 1 : 0);
    glProgramUniform3fv(p, uniform(p, "lut_max"), 1, glm::value_ptr(response_max));
    glBindTextureUnit(shaders::kLinearImageUnit, scene.color.get());
    glBindTextureUnit(shaders::kEncodedUnit, encoded_copy.color.get());
    glBindTextureUnit(shaders::kUndistortionMapUnit, undistortion_map.get());
    glBindTextureUnit(shaders::kResponseDecodeUnit, response_decode.get());
    glBindTextureUnit(shaders::kResponseEncodeUnit, response_encode.get());
    draw_fullscreen();
    glDisable(GL_SCISSOR_TEST);
  }

  // At one camera pose and the objects' poses: the proxy's depth and the receivers'
  // shadows over the video in `scene`, then the objects, each pixel shaded once.
  void draw_depth_and_shadows(const glm::mat4& vp) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    draw_room_depth(vp);
    if (receivers) receivers->draw(vp);  // shadows on the video, before the objects
    if (receivers && contact) contact->draw(vp);
  }
  void draw_shaded_objects(const glm::mat4& vp, float exposure) {
    // Depth first, then shade only the nearest surface: the per-pixel lighting is the
    // costly part, and a figurine's own overlapping parts would otherwise pay it twice.
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    draw_objects(depth_only.get(), vp, false, 0.0f);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    draw_objects(shaded_object.get(), vp, true, exposure);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_DEPTH_TEST);
  }

  void pose_objects(const std::vector<glm::dmat4>& T_world_model) {
    for (std::size_t i = 0; i < objects.size(); ++i) objects[i].set_pose(T_world_model[i]);
  }
  // The objects' poses as set, to put back after drawing them elsewhere.
  using KeptPoses = std::vector<std::pair<glm::mat4, glm::mat3>>;
  KeptPoses keep_poses() const {
    KeptPoses kept;
    for (const Object& o : objects) kept.emplace_back(o.model, o.normal_matrix);
    return kept;
  }
  void put_back(const KeptPoses& kept) {
    for (std::size_t i = 0; i < objects.size(); ++i) std::tie(objects[i].model, objects[i].normal_matrix) = kept[i];
  }
  static cv::Rect bounding(const cv::Rect& a, const cv::Rect& b) { return a.empty() ? b : (b.empty() ? a : (a | b)); }

  // Where the objects that move against the camera during the shutter are at any of its
  // instants (their footprints' bounding box): the only pixels the instants draw
  // differently. An object still in the camera's view adds nothing.
  cv::Rect shutter_footprint(std::span<const ShutterInstant> shutter) {
    std::vector<char> moving(objects.size(), 0);
    const glm::dmat4 first_view = glm::inverse(shutter[0].T_world_camera.matrix());
    for (std::size_t i = 0; i < objects.size(); ++i)
      for (const ShutterInstant& instant : shutter) {
        const glm::dmat4 change = glm::inverse(instant.T_world_camera.matrix()) * instant.T_world_model[i] -
                                  first_view * shutter[0].T_world_model[i];
        for (int c = 0; c < 4; ++c) moving[i] |= glm::length(change[c]) > 1e-9;
      }
    const KeptPoses kept = keep_poses();
    cv::Rect box;
    for (const ShutterInstant& instant : shutter) {
      pose_objects(instant.T_world_model);
      box = bounding(box, objects_footprint(view_projection(camera, instant.T_world_camera), &moving));
    }
    put_back(kept);
    return box;
  }

  void make_motion_targets() {
    if (still.width == camera.width && still.height == camera.height) return;
    still = RenderTarget(camera.width, camera.height, GL_RGBA32F, false, "the background kept");
    accumulated = RenderTarget(camera.width, camera.height, GL_RGBA32F, false, "the shutter's sum");
  }

  // Motion blur, within `box` of `scene`: the mean of the frame drawn at each instant of
  // the shutter over the background `still` holds there (an accumulation buffer; Haeberli
  // & Akeley 1990). Each instant costs one more drawing of the objects, antialiased as
  // the frame is; `scene` holds the frame drawn once at the poses set, and the instant
  // that is that frame is taken from it, not drawn again.
  void blur_motion(std::span<const ShutterInstant> shutter, const cv::Rect& box, const Pose& T_world_camera,
                   float exposure, bool antialiasing) {
    const KeptPoses kept = keep_poses();
    const auto is_drawn_frame = [&](const ShutterInstant& instant) {
      if (instant.T_world_camera.rotation != T_world_camera.rotation ||
          instant.T_world_camera.translation != T_world_camera.translation)
        return false;
      for (std::size_t i = 0; i < objects.size(); ++i)
        if (glm::mat4(instant.T_world_model[i]) != kept[i].first) return false;
      return true;
    };
    const float weight = 1.0f / float(shutter.size());
    const auto add_to_sum = [&] {
      begin_within(accumulated, box);
      glEnable(GL_BLEND);
      glBlendFunc(GL_ONE, GL_ONE);
      glUseProgram(weighted_copy.get());
      glProgramUniform1f(weighted_copy.get(), uniform(weighted_copy.get(), "weight"), weight);
      glBindTextureUnit(shaders::kLinearImageUnit, scene.color.get());
      draw_fullscreen();
      glDisable(GL_BLEND);
      glDisable(GL_SCISSOR_TEST);
    };
    begin_within(accumulated, box);
    const float zero[4] = {0, 0, 0, 0}, far = 1.0f;
    glClearNamedFramebufferfv(accumulated.framebuffer.get(), GL_COLOR, 0, zero);
    glDisable(GL_SCISSOR_TEST);
    std::vector<char> drawn(shutter.size(), 0);
    for (std::size_t k = 0; k < shutter.size(); ++k)
      if (is_drawn_frame(shutter[k])) {
        add_to_sum();
        drawn[k] = 1;
        break;
      }
    for (std::size_t k = 0; k < shutter.size(); ++k) {
      if (drawn[k]) continue;
      pose_objects(shutter[k].T_world_model);
      const glm::mat4 vp = view_projection(camera, shutter[k].T_world_camera);
      copy_within(still.framebuffer.get(), scene, box);
      begin_within(scene, box);
      glClearNamedFramebufferfv(scene.framebuffer.get(), GL_DEPTH, 0, &far);
      draw_depth_and_shadows(vp);
      draw_shaded_objects(vp, exposure);
      glDisable(GL_SCISSOR_TEST);
      if (antialiasing) antialias(vp, objects_footprint(vp) & box, shutter[k].T_world_camera);
      add_to_sum();
    }
    copy_within(accumulated.framebuffer.get(), scene, box);
    put_back(kept);
  }

  // Visible object positions after proxy occlusion, into `scene`; RGBA32F, row 0 at the bottom.
  void draw_positions(const Pose& T_world_camera) {
    const glm::mat4 vp = view_projection(camera, T_world_camera);
    scene.begin();
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    draw_room_depth(vp);
    draw_objects(world_position.get(), vp, false, 0.0f);
    glDisable(GL_DEPTH_TEST);
  }
};

Renderer::Renderer(const CameraIntrinsics& camera) : impl_(std::make_unique<Impl>()) {
  if (!camera.is_valid())
    throw InputError("Renderer: invalid output camera (" + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + ", fx " + std::to_string(camera.fx) +
                     "); check the camera calibration file");
  if (!any_context_current()) throw RuntimeError("Renderer: no OpenGL context is current; create a gl::Context first");
  Impl& r = *impl_;
  r.camera = camera.without_distortion();
  r.empty_vertex_array = create_vertex_array();
  using namespace shaders;
  r.background = create_program("background", kFullscreenVertex,
                                with_glsl_library(kBackgroundFragment, kCameraResponseGlsl).c_str());
  r.depth_only = create_program("proxy depth", kMeshVertex, kDepthOnlyFragment);
  r.shaded_object = create_program("shaded object", kMeshVertex,
                                   with_glsl_library(kShadedObjectFragment, kIrradianceVolumeGlsl).c_str());
  r.world_position = create_program("world position", kMeshVertex, kWorldPositionFragment);
  r.room_radiance = create_program("room radiance", kMeshVertex, kRoomRadianceFragment);
  r.encode =
      create_program("sRGB encode", kFullscreenVertex, with_glsl_library(kEncodeFragment, kCameraResponseGlsl).c_str());
  r.blur = create_program("camera blur", kFullscreenVertex, kBlurFragment);
  r.resample =
      create_program("resample", kFullscreenVertex, with_glsl_library(kResampleFragment, kCameraResponseGlsl).c_str());
  r.covered = create_program("object coverage", kMeshVertex, kCoveredFragment);
  r.antialias_resolve = create_program("antialiasing", kFullscreenVertex, kAntialiasFragment);
  r.weighted_copy = create_program("motion blur sum", kFullscreenVertex, kWeightedCopyFragment);
  r.scene = RenderTarget(camera.width, camera.height, GL_RGBA32F, true, "the linear scene");
  r.encoded = RenderTarget(camera.width, camera.height, GL_RGBA8, false, "the encoded output");
  GLint max_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  if (max_samples >= 2)
    r.multisampled = MultisampleTarget(camera.width, camera.height, std::min(4, int(max_samples)), GL_R8);
  check_gl_errors("Renderer::Renderer");
}

Renderer::~Renderer() = default;

void Renderer::set_room(const Mesh& room_world) {
  impl_->room = GpuMesh(room_world, "proxy room mesh");
  check_gl_errors("Renderer::set_room");
}

void Renderer::set_receivers(const Mesh& receivers_world) {
  if (receivers_world.indices.empty()) {
    impl_->receivers.reset();
    return;
  }
  if (!impl_->receivers) impl_->receivers = std::make_unique<ShadowPass>();
  impl_->receivers->set_receivers(receivers_world);
}

void Renderer::set_receiver_attenuation(std::span<const glm::vec3> attenuation) {
  if (!impl_->receivers) throw InputError("Renderer::set_receiver_attenuation: no receivers; call set_receivers first");
  impl_->receivers->set_attenuation(attenuation);
}

void Renderer::set_contact_receivers(const Mesh& patch_world, std::span<const glm::vec3> correction) {
  if (patch_world.indices.empty()) {
    impl_->contact.reset();
    return;
  }
  auto pass = std::make_unique<ShadowPass>();
  pass->set_receivers(patch_world);
  pass->set_attenuation(correction);
  impl_->contact = std::move(pass);
}

void Renderer::set_environment(const EnvironmentMap& map) {
  if (map.width <= 0 || map.height <= 0 || map.rgb.size() != std::size_t(map.width) * map.height * 3)
    throw InputError("Renderer::set_environment: environment map is empty or its pixel count does not match " +
                     std::to_string(map.width) + "x" + std::to_string(map.height) + "; load it again");
  Impl& r = *impl_;
  r.environment = create_texture_2d(GL_RGB32F, map.width, map.height, GL_LINEAR, GL_REPEAT, GL_CLAMP_TO_EDGE);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  // Texel row 0 is the map's top row (theta = 0), so v / H is the texture's t directly.
  glTextureSubImage2D(r.environment.get(), 0, 0, 0, map.width, map.height, GL_RGB, GL_FLOAT, map.rgb.data());
  r.capture_position = glm::vec3(map.capture_position);
  // world direction = Ry(offset) * map direction, so map direction = Ry(-offset) * world direction.
  r.map_from_world =
      glm::mat3(glm::rotate(glm::dmat4(1.0), glm::radians(-map.azimuth_offset_deg), glm::dvec3(0, 1, 0)));
  check_gl_errors("Renderer::set_environment");
}

int Renderer::add_object(const Mesh& mesh_model) {
  Impl::Object o;
  o.mesh = GpuMesh(mesh_model, "virtual object mesh", true);
  std::tie(o.lo, o.hi) = mesh_model.bounds();
  if (mesh_model.normals.empty() && !mesh_model.indices.empty())
    throw InputError("Renderer::add_object: the virtual object mesh has no normals; load it with load_mesh");
  o.mesh.set_light_attenuation(std::vector<glm::vec3>(mesh_model.positions.size(), glm::vec3(1.0f)));
  impl_->objects.push_back(std::move(o));
  check_gl_errors("Renderer::add_object");
  return int(impl_->objects.size()) - 1;
}

void Renderer::set_object_pose(int id, const glm::dmat4& T_world_model) {
  impl_->object(id, "set_object_pose").set_pose(T_world_model);
}

void Renderer::set_object_light_attenuation(int id, std::span<const glm::vec3> attenuation) {
  impl_->object(id, "set_object_light_attenuation").mesh.set_light_attenuation(attenuation);
  check_gl_errors("Renderer::set_object_light_attenuation");
}

void Renderer::set_object_bounce_light(int id, std::span<const glm::vec3> irradiance) {
  impl_->object(id, "set_object_bounce_light").mesh.set_bounce_light(irradiance);
  check_gl_errors("Renderer::set_object_bounce_light");
}

void Renderer::set_object_vertex_irradiance(int id, std::span<const glm::vec3> irradiance) {
  Impl::Object& o = impl_->object(id, "set_object_vertex_irradiance");
  if (!irradiance.empty()) o.mesh.set_vertex_irradiance(irradiance);
  o.vertex_lit = !irradiance.empty();
  check_gl_errors("Renderer::set_object_vertex_irradiance");
}

void Renderer::set_object_lights_blocked(int id, std::span<const float> blocked) {
  impl_->object(id, "set_object_lights_blocked").mesh.set_lights_blocked(blocked);
  check_gl_errors("Renderer::set_object_lights_blocked");
}

void Renderer::set_object_self_occlusion(int id, std::span<const VertexOcclusion> occlusion) {
  std::vector<glm::vec4> packed(occlusion.size());
  for (std::size_t i = 0; i < occlusion.size(); ++i) packed[i] = glm::vec4(occlusion[i].bent_normal, occlusion[i].open);
  impl_->object(id, "set_object_self_occlusion").mesh.set_self_occlusion(packed);
  check_gl_errors("Renderer::set_object_self_occlusion");
}

void Renderer::set_features(const CompositeFeatures& features) { impl_->features = features; }

const CompositeFeatures& Renderer::features() const { return impl_->features; }

void Renderer::set_coverage_mesh_error(double pixels) {
  if (!(pixels >= 0.0 && pixels <= kMaxCoverageErrorPx))
    throw InputError("Renderer::set_coverage_mesh_error: " + std::to_string(pixels) +
                     " pixels; use 0 (the meshes as given) to " + std::to_string(int(kMaxCoverageErrorPx)));
  impl_->coverage_error_px = float(pixels);
}

double Renderer::coverage_mesh_error() const { return impl_->coverage_error_px; }

std::size_t Renderer::coverage_triangles() const {
  std::size_t n = 0;
  for (const Impl::Object& o : impl_->objects) n += o.mesh.empty() ? 0 : o.mesh.triangles(o.level);
  return n;
}

void Renderer::set_object_material(int id, const glm::vec3& albedo, const SH9& irradiance_sh) {
  Impl::Object& o = impl_->object(id, "set_object_material");
  o.albedo = albedo;
  for (int i = 0; i < 9; ++i) o.sh[std::size_t(i)] = glm::vec3(irradiance_sh.coefficients[std::size_t(i)]);
}

void Renderer::set_irradiance_volume(const IrradianceVolume* volume) {
  // The same volume relit (a fade of the room's light) updates its light in place.
  if (volume && impl_->volume && impl_->volume->update_lighting(*volume)) return;
  impl_->volume = volume ? std::make_unique<IrradianceTextures>(*volume) : nullptr;
  check_gl_errors("Renderer::set_irradiance_volume");
}

void Renderer::set_undistortion_map(const cv::Mat& map_x, const cv::Mat& map_y) {
  Impl& r = *impl_;
  const cv::Size size(r.camera.width, r.camera.height);
  if (map_x.type() != CV_32FC1 || map_y.type() != CV_32FC1 || map_x.size() != size || map_y.size() != size)
    throw InputError("Renderer::set_undistortion_map: maps must be CV_32FC1 of the output size " +
                     std::to_string(size.width) + "x" + std::to_string(size.height) +
                     "; make them with cv::initUndistortRectifyMap(..., CV_32FC1, ...)");
  cv::Mat xy;
  cv::merge(std::vector<cv::Mat>{map_x, map_y}, xy);
  r.undistortion_map =
      create_texture_2d(GL_RG32F, size.width, size.height, GL_NEAREST, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTextureSubImage2D(r.undistortion_map.get(), 0, 0, 0, size.width, size.height, GL_RG, GL_FLOAT, xy.data);
  check_gl_errors("Renderer::set_undistortion_map");
}

void Renderer::set_video_radiometry(const VideoRadiometry& radiometry) {
  Impl& r = *impl_;
  if (!std::isfinite(radiometry.vignetting_a) || !std::isfinite(radiometry.vignetting_b))
    throw InputError("Renderer::set_video_radiometry: vignetting coefficients must be finite");
  for (int c = 0; c < 3; ++c) {
    const float read = radiometry.noise_read_variance[std::size_t(c)],
                shot = radiometry.noise_shot_gain[std::size_t(c)];
    if (!std::isfinite(read) || !std::isfinite(shot) || read < 0 || shot < 0)
      throw InputError("Renderer::set_video_radiometry: noise variances must be finite and non-negative");
  }
  if (!std::isfinite(radiometry.blur_sigma_px) || radiometry.blur_sigma_px < 0 || radiometry.blur_sigma_px > 4)
    throw InputError("Renderer::set_video_radiometry: blur sigma must be between 0 and 4 pixels");
  for (const int block : {radiometry.chroma_horizontal, radiometry.chroma_vertical})
    if (block != 1 && block != 2)
      throw InputError("Renderer::set_video_radiometry: " + std::to_string(block) +
                       " pixels per chroma sample; the codecs it follows share one among 1 or 2 each way");
  r.vignetting = glm::vec2(float(radiometry.vignetting_a), float(radiometry.vignetting_b));
  r.video_camera = radiometry.video_camera;
  for (int c = 0; c < 3; ++c) {  // BGR -> RGB
    r.noise_read_variance[c] = radiometry.noise_read_variance[std::size_t(2 - c)];
    r.noise_shot_gain[c] = radiometry.noise_shot_gain[std::size_t(2 - c)];
  }
  r.blur_sigma = float(radiometry.blur_sigma_px);
  r.chroma_block = glm::ivec2(radiometry.chroma_horizontal, radiometry.chroma_vertical);
  if (radiometry.linear_of_code.empty()) {
    r.response_decode = GlName();
    r.response_encode = GlName();
    return;
  }
  const auto& table = radiometry.linear_of_code;
  if (table.size() != 3)
    throw InputError("Renderer::set_video_radiometry: the response needs 3 channels, got " +
                     std::to_string(table.size()));
  for (const auto& channel : table)
    for (int code = 0; code < 256; ++code)
      if (!std::isfinite(channel[std::size_t(code)]) || channel[std::size_t(code)] < 0.0f ||
          (code > 0 && channel[std::size_t(code)] < channel[std::size_t(code - 1)]))
        throw InputError(
            "Renderer::set_video_radiometry: the response is not finite, non-negative and "
            "non-decreasing at code " +
            std::to_string(code) + "; recalibrate it");
  // Decode: the table itself, RGB order. Encode: its inverse sampled at linear = s^2 * max,
  // dense near black where codes are closest together in linear terms.
  constexpr int kEncodeSize = 4096;
  std::vector<float> decode(256 * 3), encode(kEncodeSize * 3);
  for (int c = 0; c < 3; ++c) {
    const auto& lut = table[std::size_t(2 - c)];  // BGR -> RGB
    r.response_max[c] = std::max(lut[255], 1e-12f);
    for (int code = 0; code < 256; ++code) decode[std::size_t(code * 3 + c)] = lut[std::size_t(code)];
    int code = 0;
    for (int i = 0; i < kEncodeSize; ++i) {
      const float s = float(i) / float(kEncodeSize - 1), linear = s * s * r.response_max[c];
      while (code < 254 && lut[std::size_t(code + 1)] < linear) ++code;
      const float lo = lut[std::size_t(code)], hi = lut[std::size_t(code + 1)];
      const float f = hi > lo ? std::clamp((linear - lo) / (hi - lo), 0.0f, 1.0f) : (linear >= hi ? 1.0f : 0.0f);
      encode[std::size_t(i * 3 + c)] = (float(code) + f) / 255.0f;
    }
  }
  r.response_decode = create_texture_2d(GL_RGB32F, 256, 1, GL_LINEAR, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
  r.response_encode = create_texture_2d(GL_RGB32F, kEncodeSize, 1, GL_LINEAR, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTextureSubImage2D(r.response_decode.get(), 0, 0, 0, 256, 1, GL_RGB, GL_FLOAT, decode.data());
  glTextureSubImage2D(r.response_encode.get(), 0, 0, 0, kEncodeSize, 1, GL_RGB, GL_FLOAT, encode.data());
  check_gl_errors("Renderer::set_video_radiometry");
}

cv::Mat Renderer::render_overlay(const cv::Mat& video_bgr8, const std::optional<Pose>& T_world_camera, double exposure,
                                 OverlayTimings* timings, std::span<const ShutterInstant> shutter) {
  if (video_bgr8.type() != CV_8UC3 || video_bgr8.empty())
    throw InputError("Renderer::render_overlay: video frame must be non-empty BGR8 (CV_8UC3); convert it first");
  Impl& r = *impl_;
  for (const ShutterInstant& instant : shutter)
    if (instant.T_world_model.size() != r.objects.size())
      throw InputError("Renderer::render_overlay: a shutter instant has " +
                       std::to_string(instant.T_world_model.size()) + " object poses for " +
                       std::to_string(r.objects.size()) + " objects");
  OverlayTimings t;
  if (timings) {  // the compositor's, before this call
    t.shadows_ms = timings->shadows_ms;
    t.vertex_light_ms = timings->vertex_light_ms;
  }
  StageClock clock(timings != nullptr);

  r.upload_video(video_bgr8);
  clock.mark(&t.upload_ms);

  // Background: the undistorted video, decoded to linear light.
  r.scene.begin();
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  const GLuint bg = r.background.get();
  glUseProgram(bg);
  glProgramUniform1i(bg, uniform(bg, "use_undistortion_map"), r.undistortion_map ? 1 : 0);
  glProgramUniform2f(bg, uniform(bg, "output_size"), float(r.camera.width), float(r.camera.height));
  glBindTextureUnit(shaders::kVideoUnit, r.video.get());
  glBindTextureUnit(shaders::kUndistortionMapUnit, r.undistortion_map.get());
  glProgramUniform1i(bg, uniform(bg, "use_response_lut"), r.response_decode ? 1 : 0);
  glBindTextureUnit(shaders::kResponseDecodeUnit, r.response_decode.get());
  r.draw_fullscreen();
  clock.mark(&t.background_ms);

  // Motion blur draws the objects again at each instant, over the background kept here.
  const bool motion_blur = T_world_camera && r.features.motion_blur && shutter.size() >= 2;
  const cv::Rect moving = motion_blur ? r.shutter_footprint(shutter) : cv::Rect();
  if (!moving.empty()) {
    r.make_motion_targets();
    Impl::copy_within(r.scene.framebuffer.get(), r.still, moving);
  }

  // Without a pose there is nothing to place: the video alone, never a guessed object.
  if (T_world_camera) {
    const glm::mat4 vp = Impl::view_projection(r.camera, *T_world_camera);
    r.draw_depth_and_shadows(vp);
    clock.mark(&t.depth_ms);
    r.draw_shaded_objects(vp, float(exposure));
    clock.mark(&t.objects_ms);
  }
  // Antialiasing and blur change `scene` in place, only within the objects' footprint.
  const bool antialiasing = r.features.antialiasing && r.multisampled.samples > 1;
  const bool blur = r.features.blur && r.blur_sigma > 0.0f;
  const bool chroma = r.features.chroma && r.chroma_block != glm::ivec2(1);
  // The blur's part that follows the clipping: the undistortion's resampling (resample_rendered).
  const bool resample = T_world_camera && r.features.blur && r.undistortion_map;
  const glm::mat4 vp = T_world_camera ? Impl::view_projection(r.camera, *T_world_camera) : glm::mat4(1.0f);
  const cv::Rect footprint =
      T_world_camera && (antialiasing || blur || chroma || resample) ? r.objects_footprint(vp) : cv::Rect();
  if (T_world_camera && antialiasing) {
    r.antialias(vp, footprint, *T_world_camera);
    clock.mark(&t.antialiasing_ms);
  }
  if (!moving.empty()) {
    r.blur_motion(shutter, moving, *T_world_camera, float(exposure), antialiasing);
    clock.mark(&t.motion_blur_ms);
  }
  if (T_world_camera && blur) {
    r.blur_rendered(Impl::bounding(footprint, moving));
    clock.mark(&t.blur_ms);
  }

  // Encode to sRGB 8-bit (rows flipped) and read back top row first.
  r.encoded.begin();
  const GLuint enc = r.encode.get();
  glUseProgram(enc);
  glProgramUniform1i(enc, uniform(enc, "use_response_lut"), r.response_encode ? 1 : 0);
  glProgramUniform3fv(enc, uniform(enc, "lut_max"), 1, glm::value_ptr(r.response_max));
  // Without an undistortion map the video is the output camera's image.
  const bool mapped = bool(r.undistortion_map) && r.video_camera.is_valid();
  const CameraIntrinsics& vc = mapped ? r.video_camera : r.camera;
  glProgramUniform1i(enc, uniform(enc, "use_undistortion_map"), mapped ? 1 : 0);
  glProgramUniform2f(enc, uniform(enc, "principal_point"), float(vc.cx), float(vc.cy));
  glProgramUniform1f(enc, uniform(enc, "half_diagonal"), 0.5f * std::hypot(float(vc.width), float(vc.height)));
  glBindTextureUnit(shaders::kUndistortionMapUnit, r.undistortion_map.get());
  glProgramUniform2fv(enc, uniform(enc, "vignetting"), 1, glm::value_ptr(r.vignetting));
  glBindTextureUnit(shaders::kLinearImageUnit, r.scene.color.get());
  glBindTextureUnit(shaders::kResponseEncodeUnit, r.response_encode.get());
  const bool noise =
      r.features.noise && (r.noise_read_variance != glm::vec3(0.0f) || r.noise_shot_gain != glm::vec3(0.0f));
  glProgramUniform1i(enc, uniform(enc, "use_noise"), noise ? 1 : 0);
  glProgramUniform3fv(enc, uniform(enc, "noise_read_variance"), 1, glm::value_ptr(r.noise_read_variance));
  glProgramUniform3fv(enc, uniform(enc, "noise_shot_gain"), 1, glm::value_ptr(r.noise_shot_gain));
  glProgramUniform1ui(enc, uniform(enc, "noise_seed"), r.frame_number++);
  glBindTextureUnit(shaders::kResponseDecodeUnit, r.response_decode.get());
  // Chroma mixes a pixel with neighbours up to 3 px away (2 before it, 3 after): only
  // there can a rendered pixel change what the video shows.
  const cv::Rect mixed = chroma && T_world_camera ? r.grown(Impl::bounding(footprint, moving), 3) : cv::Rect();
  glProgramUniform2i(enc, uniform(enc, "chroma_block"), mixed.empty() ? 1 : r.chroma_block.x,
                     mixed.empty() ? 1 : r.chroma_block.y);
  glProgramUniform4i(enc, uniform(enc, "chroma_region"), mixed.x, mixed.y, mixed.br().x, mixed.br().y);
  r.draw_fullscreen();
  double encode_ms = 0;
  if (resample) {
    clock.mark(&encode_ms);
    // Rendered pixels reach as far as the blur spread them.
    r.resample_rendered(r.grown(Impl::bounding(footprint, moving), blur ? r.blur_radius() : 0));
    double resample_ms = 0;
    clock.mark(&resample_ms);
    t.blur_ms += resample_ms;
  }
  cv::Mat out(r.camera.height, r.camera.width, CV_8UC3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glReadPixels(0, 0, out.cols, out.rows, GL_BGR, GL_UNSIGNED_BYTE, out.data);
  clock.mark(&t.readback_ms);
  t.readback_ms += encode_ms;
  check_gl_errors("Renderer::render_overlay");
  if (timings) *timings = t;
  return out;
}

cv::Mat Renderer::render_room_radiance(const CameraIntrinsics& camera, const Pose& T_world_camera, cv::Mat* map_uv) {
  Impl& r = *impl_;
  if (!camera.is_valid())
    throw InputError("Renderer::render_room_radiance: invalid camera (" + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + "); check its intrinsics");
  if (!r.environment)
    throw RuntimeError("Renderer::render_room_radiance: no environment map; call set_environment first");
  if (r.room_target.width != camera.width || r.room_target.height != camera.height)
    r.room_target = RenderTarget(camera.width, camera.height, GL_RGBA32F, true, "the room radiance");

  const glm::mat4 vp = Impl::view_projection(camera.without_distortion(), T_world_camera);
  const GLuint p = r.room_radiance.get();
  const auto draw = [&](bool map_coordinates) {
    r.room_target.begin();
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glUseProgram(p);
    Impl::set_transform(p, glm::mat4(1.0f), glm::mat3(1.0f), vp);
    glProgramUniform3fv(p, uniform(p, "capture_position"), 1, glm::value_ptr(r.capture_position));
    glProgramUniformMatrix3fv(p, uniform(p, "map_from_world"), 1, GL_FALSE, glm::value_ptr(r.map_from_world));
    glProgramUniform1i(p, uniform(p, "map_coordinates"), map_coordinates ? 1 : 0);
    glBindTextureUnit(shaders::kEnvironmentUnit, r.environment.get());
    r.room.draw();
    glDisable(GL_DEPTH_TEST);
  };
  if (map_uv) {
    draw(true);
    const cv::Mat rgba =
        read_float_pixels(camera.width, camera.height, GL_RGBA, CV_32FC4, "Renderer::render_room_radiance");
    cv::Mat channels[4];
    cv::split(rgba, channels);
    cv::merge(channels, 2, *map_uv);
    map_uv->setTo(cv::Scalar(-1.0f, -1.0f), channels[3] < 0.5f);  // no room there
  }
  draw(false);
  return read_float_pixels(camera.width, camera.height, GL_BGR, CV_32FC3, "Renderer::render_room_radiance");
}

cv::Mat Renderer::render_object_world_positions(const Pose& T_world_camera) {
  Impl& r = *impl_;
  r.draw_positions(T_world_camera);
  return read_float_pixels(r.camera.width, r.camera.height, GL_RGBA, CV_32FC4,
                           "Renderer::render_object_world_positions");
}

cv::Mat Renderer::render_object_mask(const Pose& T_world_camera) {
  cv::Mat w;
  cv::extractChannel(render_object_world_positions(T_world_camera), w, 3);
  return w > 0.5f;
}

}  // namespace lumar::gl
