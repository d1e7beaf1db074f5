#include "lumar/sim/synthetic_board.h"

#include <spdlog/spdlog.h>
#include <cmath>
#include <mutex>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/capture/recording_writer.h"
#include "lumar/capture/session.h"
#include "lumar/sim/synthetic_recording.h"
#include "lumar/tracking/rig.h"
#include "lumar/tracking/simulated_tracker.h"

namespace lumar::sim {

namespace {

constexpr double kBlack = 30, kWhite = 220, kBackground = 110;

// Integral of the square wave that is +1 on [2k s, (2k+1) s) and -1 elsewhere: a
// triangle wave between 0 and s.
double square_wave_integral(double x, double s) {
  const double u = x / s;
  const double m = u - 2.0 * std::floor(0.5 * u);  // in [0, 2)
  return s * (1.0 - std::abs(m - 1.0));
}

// Length of [a, b] inside [lo, hi], and the square wave's integral over that part.
void clipped(double a, double b, double lo, double hi, double s, double& length, double& wave) {
  const double x0 = std::max(a, lo), x1 = std::min(b, hi);
  if (x1 <= x0) {
    length = wave = 0;
    return;
  }
  length = x1 - x0;
  wave = square_wave_integral(x1, s) - square_wave_integral(x0, s);
}

// Normalised image coordinates of every pixel corner (u - 1/2, v - 1/2): the lens's
// distortion undone once, since it is the same for every frame.
struct CornerRays {
  int w = 0, h = 0;  // (width + 1) x (height + 1) corners
  std::vector<cv::Point2d> xy;
};

CornerRays corner_rays(const CameraIntrinsics& camera) {
  CornerRays rays;
  rays.w = camera.width + 1, rays.h = camera.height + 1;
  std::vector<cv::Point2d> pixels;
  pixels.reserve(std::size_t(rays.w) * std::size_t(rays.h));
  for (int v = 0; v < rays.h; ++v)
    for (int u = 0; u < rays.w; ++u) pixels.emplace_back(u - 0.5, v - 0.5);
  cv::undistortPoints(pixels, rays.xy, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients(), cv::noArray(),
                      cv::noArray(), cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
  return rays;
}

const CornerRays& cached_rays(const CameraIntrinsics& camera) {
  static std::mutex mutex;
  static CameraIntrinsics key;
  static CornerRays rays;
  std::lock_guard lock(mutex);
  if (rays.xy.empty() || key.width != camera.width || key.height != camera.height || key.fx != camera.fx ||
      key.fy != camera.fy || key.cx != camera.cx || key.cy != camera.cy || key.distortion != camera.distortion) {
    rays = corner_rays(camera);
    key = camera;
  }
  return rays;
}

}  // namespace

Pose board_synth_T_world_board() { return Pose{axis_angle_deg({1, 0, 0}, 90.0), {0, 0, 0}}; }

Pose board_synth_T_sensor_camera() {
  return Pose{axis_angle_deg(glm::normalize(glm::dvec3(0.15, -0.2, 1.0)), 95.0), {0.035, -0.048, 0.021}};
}

Pose board_synth_T_world_transmitter() {
  // On the table beside the board, +Z (Polhemus down) along world -Y, turned 30 degrees.
  return Pose{axis_angle_deg({0, 1, 0}, 30.0) * axis_angle_deg({1, 0, 0}, 90.0), {0.35, -0.02, 0.30}};
}

Pose board_synth_camera_pose(double t, cv::Size board, double square) {
  const Pose T_world_board = board_synth_T_world_board();
  const glm::dvec3 centre =
      T_world_board.apply({0.5 * (board.width - 1) * square, 0.5 * (board.height - 1) * square, 0.0});
  const double size = std::max(board.width + 1, board.height + 1) * square;  // board's long side
  const double az = glm::radians(40.0 * std::sin(2 * kPi * 0.21 * t) + 12.0 * std::sin(2 * kPi * 0.53 * t + 0.4));
  const double el = glm::radians(58.0 + 14.0 * std::sin(2 * kPi * 0.29 * t + 1.0));
  const double distance = size * (2.0 + 0.25 * std::sin(2 * kPi * 0.17 * t + 2.0));
  const double roll = 20.0 * std::sin(2 * kPi * 0.37 * t + 2.0) + 8.0 * std::sin(2 * kPi * 0.71 * t);
  const glm::dvec3 eye =
      centre + distance * glm::dvec3(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
  const glm::dvec3 wander = 0.06 * size * glm::dvec3(std::sin(2 * kPi * 0.43 * t), 0.0, std::cos(2 * kPi * 0.31 * t));
  Pose p = look_at(eye, centre + wander);
  p.rotation = glm::normalize(p.rotation * axis_angle_deg({0, 0, 1}, roll));  // about the view axis
  return p;
}

cv::Mat render_board_image(const CameraIntrinsics& camera, cv::Size board, double square, const Pose& T_camera_board) {
  const CornerRays& rays = cached_rays(camera);
  // Board point (X, Y, 1) -> camera ray: H = [r1 r2 t]; a ray (x, y, 1) hits the board at H^-1 (x, y, 1).
  const glm::dmat3 R = T_camera_board.rotation_matrix();
  cv::Matx33d H;
  for (int r = 0; r < 3; ++r) {
    H(r, 0) = R[0][r];
    H(r, 1) = R[1][r];
    H(r, 2) = T_camera_board.translation[r];
  }
  const cv::Matx33d Hinv = H.inv();
  const double s = square;
  const double cx0 = -s, cx1 = board.width * s, cy0 = -s, cy1 = board.height * s;  // the squares
  const double bx0 = cx0 - s, bx1 = cx1 + s, by0 = cy0 - s, by1 = cy1 + s;         // white margin, one square
  const double far = 1e3;  // rays that miss the plane (behind the camera) land here, off the board

  std::vector<cv::Point2d> plane(rays.xy.size());
  cv::parallel_for_(cv::Range(0, rays.h), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v)
      for (int u = 0; u < rays.w; ++u) {
        const std::size_t i = std::size_t(v) * std::size_t(rays.w) + std::size_t(u);
        const cv::Vec3d b = Hinv * cv::Vec3d(rays.xy[i].x, rays.xy[i].y, 1.0);
        plane[i] = b[2] > 1e-12 ? cv::Point2d(b[0] / b[2], b[1] / b[2]) : cv::Point2d(far, far);
      }
  });
  cv::Mat image(camera.height, camera.width, CV_8UC1);
  cv::parallel_for_(cv::Range(0, camera.height), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      uchar* row = image.ptr<uchar>(v);
      for (int u = 0; u < camera.width; ++u) {
        const std::size_t i = std::size_t(v) * std::size_t(rays.w) + std::size_t(u);
        const cv::Point2d& a = plane[i];
        const cv::Point2d& b = plane[i + 1];
        const cv::Point2d& c = plane[i + std::size_t(rays.w)];
        const cv::Point2d& d = plane[i + std::size_t(rays.w) + 1];
        // The pixel's footprint on the board, as its bounding box.
        const double x0 = std::min({a.x, b.x, c.x, d.x}), x1 = std::max({a.x, b.x, c.x, d.x});
        const double y0 = std::min({a.y, b.y, c.y, d.y}), y1 = std::max({a.y, b.y, c.y, d.y});
        const double area = std::max((x1 - x0) * (y1 - y0), 1e-30);
        double lx, wx, ly, wy, bx, by, unused;
        clipped(x0, x1, cx0, cx1, s, lx, wx);
        clipped(y0, y1, cy0, cy1, s, ly, wy);
        clipped(x0, x1, bx0, bx1, s, bx, unused);
        clipped(y0, y1, by0, by1, s, by, unused);
        const double squares = lx * ly, margin = bx * by - squares, outside = area - bx * by;
        // Over the squares: mean grey minus half the contrast times the product wave
        // (+1 on squares whose indices sum to an even number: those are black).
        const double sum = 0.5 * (kWhite + kBlack) * squares - 0.5 * (kWhite - kBlack) * wx * wy + kWhite * margin +
                           kBackground * std::max(0.0, outside);
        row[u] = cv::saturate_cast<uchar>(sum / area);
      }
    }
  });
  return image;
}

void synthesize_board_recording(const BoardSynthSettings& s) {
  if (s.board.width < 2 || s.board.height < 2) throw InputError("--board: give the inner corners, e.g. 9x6");
  if (!(s.square > 0)) throw InputError("--square: must be a positive length in metres");
  if (!(s.fps > 0) || !(s.seconds > 0)) throw InputError("--fps and --seconds must be positive");
  if (s.latency_ms < 0 || s.assumed_latency_ms < 0) throw InputError("--latency-ms: must not be negative");
  if (std::filesystem::exists(s.out))
    throw InputError(s.out.string() + ": already exists; choose a new recording directory");

  const Pose T_world_board = board_synth_T_world_board();
  tracking::Rig truth;
  truth.T_world_transmitter = board_synth_T_world_transmitter();
  truth.T_sensor_camera = board_synth_T_sensor_camera();
  truth.latency = seconds_to_nanos(s.latency_ms * 1e-3);

  // The session as a recorder would write it before calibration: an identity rig and
  // the latency it assumed. The truth sits beside it.
  capture::Session session;
  session.camera = s.camera;
  session.rig.latency = seconds_to_nanos(s.assumed_latency_ms * 1e-3);
  session.source = "lumar synth --board";
  capture::BoardSynthInfo info;
  info.board = std::to_string(s.board.width) + "x" + std::to_string(s.board.height);
  info.square = s.square;
  info.seconds = s.seconds;
  info.fps = s.fps;
  info.tracker_noise_deg = s.tracker_noise_deg;
  info.position_noise_m = s.position_noise_m;
  info.image_noise = s.image_noise;
  info.seed = s.seed;
  info.truth = truth;
  info.T_world_board = T_world_board;
  session.synth_board = info;

  // Half a second of tracker on either side of the video, so that a wrong assumed
  // latency still leaves tracker poses around every frame.
  const Nanos start = seconds_to_nanos(0.5);
  const Nanos frame_period = seconds_to_nanos(1.0 / s.fps);
  const int frames = std::max(2, int(std::lround(s.seconds * s.fps)));
  const Nanos duration = start + frame_period * frames + seconds_to_nanos(0.5);
  auto true_camera = [&](Nanos t) { return board_synth_camera_pose(nanos_to_seconds(t), s.board, s.square); };

  const auto tracker = simulate_session_tracker(
      session, truth.latency, s.tracker_noise_deg, s.position_noise_m, s.seed,
      [&](Nanos t) { return truth.sensor_pose(true_camera(t)); }, duration);

  const capture::RecordingSettings video{
      .codec = s.codec, .fps = s.fps, .size = cv::Size(s.camera.width, s.camera.height)};
  cv::Mat noise(video.size, CV_32F), grey, bgr;
  write_synthetic_recording(
      s.out, session, tracker, video, frames, s.seed, [&](int k) { return start + frame_period * k; }, true_camera,
      [&](int, Nanos, const Pose& T_world_camera, cv::RNG& rng) {
        render_board_image(s.camera, s.board, s.square, T_world_camera.inverse() * T_world_board)
            .convertTo(grey, CV_32F);
        rng.fill(noise, cv::RNG::NORMAL, 0.0, s.image_noise);
        cv::Mat(grey + noise).convertTo(grey, CV_8U);  // rounds and clips
        cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
        return bgr.clone();
      });
  spdlog::info("synth: wrote {} ({} frames of a {}x{} board, tracker {} records, latency {} ms, assumed {} ms)",
               s.out.string(), frames, s.board.width, s.board.height, tracker.noisy_samples.size(), s.latency_ms,
               s.assumed_latency_ms);
}

}  // namespace lumar::sim
