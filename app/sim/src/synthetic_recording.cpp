#include "lumar/sim/synthetic_recording.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/base/stop_signal.h"
#include "lumar/calib/image_file.h"
#include "lumar/calib/undistortion.h"
#include "lumar/capture/recording_writer.h"
#include "lumar/capture/session.h"
#include "lumar/lighting/composite_reference.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/render/platform/context.h"
#include "lumar/render/renderer.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/sim/envmap_view.h"
#include "lumar/sim/furnished_room.h"
#include "lumar/sim/truth_frame.h"
#include "lumar/tracking/simulated_tracker.h"
#include "lumar/tracking/tracker_stream.h"

namespace lumar::sim {

Pose look_at(const glm::dvec3& eye, const glm::dvec3& target) {
  const glm::dvec3 forward = glm::normalize(target - eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
  const glm::dvec3 down = glm::cross(forward, right);
  Pose p;
  p.rotation = glm::normalize(glm::quat_cast(glm::dmat3(right, down, forward)));
  p.translation = eye;
  return p;
}

tracking::SimulatedTrackerOutput simulate_session_tracker(const capture::Session& session, Nanos device_latency,
                                                          double orientation_noise_deg, double position_noise_m,
                                                          std::uint64_t seed,
                                                          const std::function<Pose(Nanos)>& true_sensor_pose,
                                                          Nanos duration) {
  tracking::SimulatedTrackerSettings ts;
  ts.rate_hz = session.tracker.rate_hz;
  ts.baud = session.tracker.baud;
  ts.station = session.tracker.station;
  ts.device_latency = device_latency;
  ts.orientation_noise_deg = orientation_noise_deg;
  ts.position_noise_m = position_noise_m;
  ts.seed = seed;
  return tracking::simulate_tracker(true_sensor_pose, duration, ts);
}

void write_tracker_stream(capture::RecordingWriter& writer, const tracking::SimulatedTrackerOutput& tracker,
                          const capture::TrackerSettings& settings, Nanos assumed_latency) {
  for (const auto& chunk : tracker.chunks) writer.add_tracker_bytes(chunk);
  const auto decoded = tracking::decode_tracker_stream(tracker.chunks, capture::tracker_format_of(settings, "synth"),
                                                       settings.baud, assumed_latency);
  for (const auto& sample : decoded.samples) writer.add_pose(sample);
}

void write_synthetic_recording(const std::filesystem::path& out, const capture::Session& session,
                               const tracking::SimulatedTrackerOutput& tracker, const capture::RecordingSettings& video,
                               int frames, std::uint64_t seed, const std::function<Nanos(int)>& frame_time,
                               const std::function<Pose(Nanos)>& true_camera, const SyntheticFrameRenderer& render,
                               const std::function<bool(int)>& dropped) {
  try {
    capture::RecordingWriter writer(out, capture::session_to_json(session), video);
    write_tracker_stream(writer, tracker, session.tracker, session.rig.latency);
    cv::RNG rng(seed);
    for (int k = 0; k < frames; ++k) {
      if (stop_requested())
        throw Interrupted(
            fmt::format("synth: at frame {} of {}; {} removed, as an unfinished recording", k, frames, out.string()));
      if (dropped && dropped(k)) continue;
      const Nanos t = frame_time(k);
      const Pose T_world_camera = true_camera(t);
      writer.add_frame(capture::Frame{render(k, t, T_world_camera, rng), t, k});
      writer.add_truth(k, t, T_world_camera);
      if ((k + 1) % std::max(1, frames / 4) == 0 || k + 1 == frames) spdlog::info("synth: frame {}/{}", k + 1, frames);
    }
    writer.close();
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove_all(out, ec);
    throw;
  }
}

namespace {

// A pinhole camera, `supersample` times finer than `camera`, wide enough to cover
// every ray of the distorted camera (barrel distortion sees past the pinhole frame).
CameraIntrinsics covering_pinhole(const CameraIntrinsics& camera, int supersample) {
  std::vector<cv::Point2f> border;
  for (int x = 0; x < camera.width; x += 8) {
    border.emplace_back(x, 0);
    border.emplace_back(x, camera.height - 1);
  }
  for (int y = 0; y < camera.height; y += 8) {
    border.emplace_back(0, y);
    border.emplace_back(camera.width - 1, y);
  }
  border.emplace_back(camera.width - 1, camera.height - 1);
  std::vector<cv::Point2f> normalized;
  cv::undistortPoints(border, normalized, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients());
  float x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  for (const auto& p : normalized) {
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  CameraIntrinsics pin;
  const double s = supersample, pad = 4;  // pixels of the pinhole image beyond the rays
  pin.fx = camera.fx * s;
  pin.fy = camera.fy * s;
  pin.cx = -x0 * pin.fx + pad;
  pin.cy = -y0 * pin.fy + pad;
  pin.width = int(std::ceil((x1 - x0) * pin.fx + 2 * pad));
  pin.height = int(std::ceil((y1 - y0) * pin.fy + 2 * pad));
  return pin;
}

// Radiance (linear, scene units) to an 8-bit frame as the camera would record it.
cv::Mat expose(const cv::Mat& radiance_bgr, const CameraIntrinsics& camera, const SynthSettings& s, double exposure,
               cv::RNG& rng) {
  SensorModel sensor;
  sensor.read_noise = s.read_noise;
  sensor.shot_noise_gain = s.shot_noise_gain;
  sensor.vignetting_a = s.vignetting_a;
  sensor.vignetting_b = s.vignetting_b;
  return expose_8bit(radiance_bgr, camera, sensor, exposure, rng);
}

// The video codec's loss, for frames stored apart from the video (the truth): a JPEG
// of the same quality for MJPEG (OpenCV's MJPEG writer is its own JPEG encoder, so the
// loss is alike, not the same bits), nothing for the lossless FFV1.
cv::Mat compress_like_video(const cv::Mat& frame, const SynthSettings& s) {
  if (s.codec != "mjpeg") return frame;
  std::vector<std::uint8_t> bytes;
  cv::imencode(".jpg", frame, bytes, {cv::IMWRITE_JPEG_QUALITY, s.quality});
  return cv::imdecode(bytes, cv::IMREAD_COLOR);
}

// Where the camera looks: the foot of the first virtual object (the centre of its
// world bounding box, at its lowest point), else the middle of the movement box.
glm::dvec3 scene_target(const LoadedScene& scene) {
  if (scene.objects.empty()) return 0.5 * (scene.manifest.movement_min + scene.manifest.movement_max);
  // An animated object: the middle of the ground its path covers.
  const LoadedObject& object = scene.objects.front();
  glm::dvec3 lo(1e300), hi(-1e300);
  const auto cover = [&](const glm::dmat4& T) {
    const auto [a, b] = transformed(object.model, T).bounds();
    lo = glm::min(lo, glm::dvec3(a)), hi = glm::max(hi, glm::dvec3(b));
  };
  cover(object.T_world_model);
  for (const ObjectPath::Key& key : object.path.keys()) cover(key.T_world_model);
  return {0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z)};
}

}  // namespace

Pose orbit_camera_pose(const glm::dvec3& target, double s, double arc_deg) {
  // An arc around the target that ends with the table block hiding part of the object,
  // slowly descending, with a slight bob so motion is not planar.
  const double start_deg = 100.0 - arc_deg;
  const double az = glm::radians(start_deg + arc_deg * s);
  const double radius = 1.55;
  const double height = 1.25 - 0.15 * s + 0.03 * std::sin(6.0 * s);
  const glm::dvec3 eye =
      target + glm::dvec3(radius * std::sin(az), 0.0, radius * std::cos(az)) + glm::dvec3(0, height - target.y, 0);
  return look_at(eye, target + glm::dvec3(0, 0.08, 0));
}

capture::SynthInfo synth_info(const SynthSettings& s) {
  capture::SynthInfo synth;
  synth.frames = s.frames;
  synth.fps = s.fps;
  synth.tracker_noise_deg = s.tracker_noise_deg;
  synth.position_noise_m = s.position_noise_m;
  synth.read_noise = s.read_noise;
  synth.shot_noise_gain = s.shot_noise_gain;
  synth.seed = s.seed;
  return synth;
}

Pose synth_camera_pose(const std::string& path, const glm::dvec3& target, double s, double t_s, double arc_deg) {
  if (path == "orbit") return orbit_camera_pose(target, s, arc_deg);
  if (path == "still") return orbit_camera_pose(target, 1.0, arc_deg);
  if (path == "rest-turn") {
    const Pose rest = orbit_camera_pose(target, 0.5, arc_deg);
    const double turned = kRestTurnDegPerS * (std::clamp(t_s, kRestTurnStartS, kRestTurnEndS) - kRestTurnStartS);
    return Pose{axis_angle_deg({0, 1, 0}, turned) * rest.rotation, rest.translation};
  }
  if (path == "room") {
    // Standing back at the room's far side, turning slowly across the object to the far
    // wall and up, so that the room's lights and window come into view beside the object.
    const glm::dvec3 eye = target + glm::dvec3(2.7, 1.35 - target.y, 0.5);
    const double yaw = glm::radians(180.0 + 6.0 - 14.0 * s), pitch = glm::radians(-6.0 + 14.0 * s);
    const glm::dvec3 look(std::cos(pitch) * std::cos(yaw), std::sin(pitch), -std::cos(pitch) * std::sin(yaw));
    return look_at(eye, eye + look);
  }
  throw InputError("--path " + path + ": unknown camera path; use orbit, still, room or rest-turn");
}

std::vector<SynthSettings> sample_room_light_changes(const std::filesystem::path& scene, const CameraIntrinsics& camera,
                                                     const std::filesystem::path& out_dir) {
  SynthSettings base;
  base.scene = scene;
  base.camera = camera;
  base.fps = 24;
  base.supersample = 1;
  base.path = "room";
  SynthSettings lamp = base;
  lamp.out = out_dir / "lamp-off";
  lamp.frames = 120;
  lamp.light_change = LightChange{
      .region = {{-1.45, 2.9, 0.15}, {-0.95, 3.1, 0.45}}, .scale = glm::dvec3(0.0), .brighter_than = 5.0, .at_s = 2.5};
  SynthSettings window = base;
  window.out = out_dir / "warmer-window";
  window.frames = 96;
  window.exposure = 0.065;
  window.light_change = LightChange{.region = {{-3.1, 0.3, -2.5}, {-2.9, 2.75, -0.2}},
                                    .scale = glm::dvec3(1.5, 1.0, 0.5),
                                    .at_s = 1.5,
                                    .ramp_s = 0.5};
  return {lamp, window};
}

void synthesize_recording(const SynthSettings& s) {
  if (s.frames < 2) throw InputError("--frames: need at least 2 frames");
  if (s.fps <= 0) throw InputError("--fps: must be positive");
  if (s.truth_strata < 2 || s.truth_strata > 64)
    throw InputError(fmt::format("--truth-strata {}: use 2 to 64 (N*N rays per object pixel)", s.truth_strata));
  if (!s.truth_frames.empty() && !s.truth) throw InputError("synth: --truth-frames goes with --truth");
  for (int k : s.truth_frames)
    if (k < 0 || k >= s.frames)
      throw InputError(
          fmt::format("--truth-frames: frame {} is not among the {} frames (0 to {})", k, s.frames, s.frames - 1));
  if (std::filesystem::exists(s.out))
    throw InputError(s.out.string() + ": already exists; choose a new recording directory");
  const LoadedScene scene = load_scene_files(s.scene);
  if (scene.room.triangle_count() == 0) throw InputError(s.scene.string() + ": synth needs a proxy room (room.mesh)");

  // The room the camera sees: the proxy, or one unlike it (furnished_room.h), which the
  // video and the truth are both rendered from while the overlay keeps the proxy.
  std::optional<LoadedScene> furnished;
  if (s.room_differs) furnished.emplace(scene), furnished->room = furnished_room(scene.room);
  const LoadedScene& seen_scene = furnished ? *furnished : scene;

  auto context = gl::create_headless_context();
  const CameraIntrinsics pinhole = covering_pinhole(s.camera, s.supersample);
  gl::Renderer renderer(pinhole);
  renderer.set_room(seen_scene.room);
  renderer.set_environment(scene.map);
  std::optional<EnvironmentMap> changed_map;
  if (s.light_change) {
    if (s.truth) throw InputError("synth: --truth with a light change is not supported; leave one out");
    changed_map = changed_environment_map(scene, *s.light_change);
  }
  double shown_weight = 0.0;  // of the changed map in the renderer's

  // The rig: transmitter on the table, +Z (Polhemus down) along world -Y; the sensor
  // clipped to the camera a few centimetres away, turned 90 degrees.
  capture::Session session;
  session.camera = s.camera;
  session.rig.T_world_transmitter = Pose{axis_angle_deg({1, 0, 0}, 90), {0.85, 0.72, -0.75}};
  session.rig.T_sensor_camera = Pose{axis_angle_deg({0, 0, 1}, 90), {0.03, 0.05, -0.02}};
  session.rig.latency = seconds_to_nanos(s.latency_ms * 1e-3);
  session.scene =
      std::filesystem::relative(std::filesystem::absolute(s.scene), std::filesystem::absolute(s.out)).string();
  session.source = "lumar synth";
  session.synth = synth_info(s);
  session.synth->arc_deg = s.arc_deg;
  session.synth->path = s.path;

  const glm::dvec3 target = scene_target(scene);
  const Nanos start = seconds_to_nanos(0.1);  // tracker runs before the first frame
  const Nanos frame_period = seconds_to_nanos(1.0 / s.fps);
  const Nanos duration = start + frame_period * s.frames + seconds_to_nanos(0.1);
  const double clip_seconds = nanos_to_seconds(frame_period * (s.frames - 1));
  if (s.path == "rest-turn" && clip_seconds < kRestTurnEndS + 0.5)
    throw InputError(fmt::format("--path rest-turn: the recording lasts {:.2f} s; it needs {:.1f} s (--frames / --fps)",
                                 clip_seconds, kRestTurnEndS + 0.5));
  for (const auto& [name, range] :
       {std::pair{"--drop-frames", s.faults.dropped}, std::pair{"--textureless", s.faults.textureless},
        std::pair{"--occluder", s.faults.occluder}})
    if (range.from < 0 || range.count < 0 ||
        (!range.empty() && (range.from == 0 || range.from + range.count >= s.frames)))
      throw InputError(std::string(name) + ": FROM COUNT must lie within the frames and leave the first and the last");
  if (!(s.faults.motion_blur_s >= 0.0) || s.faults.motion_blur_s * s.fps > 1.0)
    throw InputError("--motion-blur: the shutter time must be from 0 to one frame period");
  auto true_camera = [&](Nanos t) {
    const double u = std::clamp(nanos_to_seconds(t - start) / clip_seconds, 0.0, 1.0);
    return synth_camera_pose(s.path, target, u, nanos_to_seconds(t - start), s.arc_deg);
  };

  const auto tracker = simulate_session_tracker(
      session, session.rig.latency, s.tracker_noise_deg, s.position_noise_m, s.seed,
      [&](Nanos t) { return session.rig.sensor_pose(true_camera(t)); }, duration);

  // Exposure: the first view's mean radiance becomes 18 % grey unless given.
  double exposure = s.exposure;
  if (exposure <= 0) {
    const cv::Mat first = renderer.render_room_radiance(pinhole, true_camera(start));
    const cv::Scalar mean = cv::mean(first);
    const double luminance = 0.0722 * mean[0] + 0.7152 * mean[1] + 0.2126 * mean[2];
    if (!(luminance > 0)) throw InputError(s.scene.string() + ": the first view of the room is black");
    exposure = 0.18 / luminance;
  }
  session.radiometry.exposure = exposure;
  session.radiometry.vignetting_a = s.vignetting_a;
  session.radiometry.vignetting_b = s.vignetting_b;
  session.radiometry.shutter_s = s.faults.motion_blur_s;

  // The truth: the room's light on the objects physically present, by brute force, from
  // a map of 128 rows (its bright texels summed exactly, the rest by rays).
  std::unique_ptr<RoomRadiance> truth_room;
  std::unique_ptr<CompositeReference> truth;
  CompositeReferenceSettings truth_reference;
  truth_reference.object_strata = s.truth_strata;
  // Where the objects' shadows fall: the surfaces the video shows. A distant map's
  // radiance has no proxy, but the video shows it on the room's mesh (a ground plane).
  RayScene distant_map_ground;
  const RayScene* room_surfaces = nullptr;
  if (s.truth) {
    if (scene.objects.empty()) throw InputError(s.scene.string() + ": --truth needs objects in the scene");
    truth_room = scene_radiance(seen_scene, truth_radiance_settings());
    truth = std::make_unique<CompositeReference>(*truth_room, seen_scene.objects, truth_reference);
    room_surfaces = truth_room->ray_scene();
    if (!room_surfaces) {
      distant_map_ground.add_static(seen_scene.room);
      distant_map_ground.commit();
      room_surfaces = &distant_map_ground;
    }
  }
  const bool animated =
      std::any_of(scene.objects.begin(), scene.objects.end(), [](const LoadedObject& o) { return !o.path.empty(); });
  cv::RNG other_seed(s.truth_seed != 0 ? s.truth_seed : s.seed + 1);
  TruthSettings truth_settings;
  truth_settings.ratio_stride = s.truth_ratio_stride;

  const cv::Mat occluder =
      s.faults.occluder.empty() ? cv::Mat() : occluder_texture(cv::Size(pinhole.width, pinhole.height));
  const capture::RecordingSettings video{
      .codec = s.codec, .quality = s.quality, .fps = s.fps, .size = cv::Size(s.camera.width, s.camera.height)};
  write_synthetic_recording(
      s.out, session, tracker, video, s.frames, s.seed, [&](int k) { return start + frame_period * k; }, true_camera,
      [&](int k, Nanos t, const Pose& T_world_camera, cv::RNG& rng) {
        if (changed_map) {
          const double w = s.light_change->weight(nanos_to_seconds(t));
          if (w != shown_weight) renderer.set_environment(blend_environment_maps(scene.map, *changed_map, w));
          shown_weight = w;
        }
        // The shutter open around t: the camera and the room at each instant (t's first).
        struct Instant {
          Nanos t;
          Pose T_world_camera;
          cv::Mat radiance;
        };
        std::vector<Instant> shutter{{t, T_world_camera, renderer.render_room_radiance(pinhole, T_world_camera)}};
        if (s.faults.motion_blur_s > 0)
          for (int i = 0; i < VideoFaults::kBlurSamples; ++i) {
            if (2 * i + 1 == VideoFaults::kBlurSamples) continue;  // the middle one is t's
            const double at = ((i + 0.5) / VideoFaults::kBlurSamples - 0.5) * s.faults.motion_blur_s;
            const Pose camera = true_camera(t + seconds_to_nanos(at));
            shutter.push_back({t + seconds_to_nanos(at), camera, renderer.render_room_radiance(pinhole, camera)});
          }
        cv::Mat radiance = shutter[0].radiance / double(shutter.size());
        for (std::size_t i = 1; i < shutter.size(); ++i) radiance += shutter[i].radiance / double(shutter.size());
        apply_video_faults(s.faults, k, occluder, radiance);
        // The video's own noise, drawn again for the truth, so that only the objects differ.
        cv::RNG same_noise = rng;
        const cv::Mat video = expose(calib::distort_image(radiance, pinhole, s.camera), s.camera, s, exposure, rng);
        const bool truth_here =
            truth && (s.truth_frames.empty() ||
                      std::find(s.truth_frames.begin(), s.truth_frames.end(), k) != s.truth_frames.end());
        if (truth_here) {
          // The objects seen at each instant of the shutter, averaged as the video's room
          // is: a moving object's truth is blurred by its motion and the camera's.
          if (shutter.size() == 1) shutter[0].radiance = radiance;  // with the faults
          TruthFrame frame;
          for (Instant& instant : shutter) {
            if (shutter.size() > 1) apply_video_faults(s.faults, k, occluder, instant.radiance);
            if (animated) {  // the objects where their paths are at this instant
              std::vector<LoadedObject> posed = scene.objects;
              for (LoadedObject& o : posed) o.T_world_model = o.pose_at(nanos_to_seconds(instant.t));
              truth = std::make_unique<CompositeReference>(*truth_room, posed, truth_reference);
            }
            const TruthFrame seen_then = render_truth_frame(*truth, *room_surfaces, pinhole, instant.T_world_camera,
                                                            instant.radiance, truth_settings);
            const double w = 1.0 / double(shutter.size());
            if (frame.radiance.empty()) {
              frame.radiance = seen_then.radiance * w;
              frame.coverage = seen_then.coverage * w;
            } else {
              frame.radiance += seen_then.radiance * w;
              frame.coverage += seen_then.coverage * w;
            }
          }
          const cv::Mat seen = calib::distort_image(frame.radiance, pinhole, s.camera);
          const std::filesystem::path dir = s.out / "truth";
          std::filesystem::create_directories(dir);
          const auto file = [&](const char* kind) { return dir / fmt::format("{}-{:05d}.png", kind, k); };
          calib::write_image_atomically(file("frame"),
                                        compress_like_video(expose(seen, s.camera, s, exposure, same_noise), s));
          calib::write_image_atomically(file("other-seed"),
                                        compress_like_video(expose(seen, s.camera, s, exposure, other_seed), s));
          // The empty room through the same JPEG encoder as the truth: where the objects
          // change nothing the two are the same bits, so a codec's loss is not taken for a shadow.
          calib::write_image_atomically(file("empty"), compress_like_video(video, s));
          cv::Mat mask;
          cv::compare(calib::distort_image(frame.coverage, pinhole, s.camera), 0.5, mask, cv::CMP_GT);
          calib::write_image_atomically(file("mask"), mask);
        }
        return video;
      },
      [&](int k) { return s.faults.dropped.contains(k); });
  spdlog::info("synth: wrote {} ({} frames, exposure {:.4g}, tracker {} records)", s.out.string(), s.frames, exposure,
               tracker.noisy_samples.size());
}

}  // namespace lumar::sim
