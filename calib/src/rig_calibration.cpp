#include "lumar/calib/rig_calibration.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"

namespace lumar::calib {

namespace {

constexpr int kParams = 13;  // X (rotation, translation), Z (same), offset

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

std::string fmt(double v, int decimals = 1) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

Pose perturbed(const Pose& p, const double* d) {
  Pose out;
  out.rotation = glm::normalize(p.rotation * rotation_exp({d[0], d[1], d[2]}));
  out.translation = p.translation + glm::dvec3(d[3], d[4], d[5]);
  return out;
}

// Camera poses (T_board_camera) of the board views, interpolated at any time between
// two views that are close enough (frames without the board leave gaps).
struct CameraPath {
  std::vector<Nanos> times;
  std::vector<Pose> T_board_camera;
  Nanos max_gap = 0;

  std::optional<Pose> at(Nanos t) const {
    if (times.empty() || t < times.front() || t > times.back()) return std::nullopt;
    const auto it = std::lower_bound(times.begin(), times.end(), t);
    const std::size_t i = std::size_t(it - times.begin());
    if (*it == t) return T_board_camera[i];
    if (times[i] - times[i - 1] > max_gap) return std::nullopt;
    return interpolate(T_board_camera[i - 1], T_board_camera[i],
                       double(t - times[i - 1]) / double(times[i] - times[i - 1]));
  }
};

// The joint fit: X = T_sensor_camera, Z = T_transmitter_board, offset in seconds. One
// residual block per tracker sample: the sensor pose the board implies at the sample's
// time - offset against the one the tracker reported.
struct RigModel {
  const std::vector<tracking::PoseSample>* samples;
  const CameraPath* path;
  double sigma_rotation_rad, sigma_position_m;

  // Residuals of the samples in `use` (6 each); false when a camera pose is missing.
  bool residuals(const Pose& X, const Pose& Z, double offset_s, const std::vector<int>& use,
                 std::vector<double>& r) const {
    r.assign(use.size() * 6, 0.0);
    const Pose X_inv = X.inverse();
    const Nanos offset = seconds_to_nanos(offset_s);
    for (std::size_t k = 0; k < use.size(); ++k) {
      const tracking::PoseSample& sample = (*samples)[std::size_t(use[k])];
      const auto camera = path->at(sample.time - offset);
      if (!camera) return false;
      const Pose predicted = Z * *camera * X_inv;
      const Pose& measured = sample.T_transmitter_sensor;
      const glm::dvec3 rot = rotation_log(glm::conjugate(measured.rotation) * predicted.rotation);
      const glm::dvec3 pos = predicted.translation - measured.translation;
      for (int a = 0; a < 3; ++a) {
        r[6 * k + std::size_t(a)] = rot[a] / sigma_rotation_rad;
        r[6 * k + 3 + std::size_t(a)] = pos[a] / sigma_position_m;
      }
    }
    return true;
  }

  bool residuals(const Pose& X, const Pose& Z, double offset_s, const double* d, const std::vector<int>& use,
                 std::vector<double>& r) const {
    return residuals(perturbed(X, d), perturbed(Z, d + 6), offset_s + d[12], use, r);
  }
};

double sum_squares(const std::vector<double>& r) {
  double s = 0;
  for (double v : r) s += v * v;
  return s;
}

struct FitState {
  Pose X, Z;
  double offset_s = 0;
  cv::Mat covariance;  // 13 x 13, scaled by the residual variance
};

// Levenberg-Marquardt with a central-difference Jacobian; the offset's step (0.5 ms) is
// wide on purpose: interpolated tracker poses are piecewise linear in time.
void refine(const RigModel& model, const std::vector<int>& use, FitState& s, bool fit_offset) {
  const double steps[kParams] = {1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 5e-4};
  const int n = fit_offset ? kParams : kParams - 1;
  std::vector<double> r, rp, rm;
  double lambda = 1e-3;
  auto jacobian = [&](cv::Mat& J) {
    J = cv::Mat::zeros(int(use.size() * 6), n, CV_64F);
    for (int j = 0; j < n; ++j) {
      double d[kParams] = {};
      d[j] = steps[j];
      const bool ok_p = model.residuals(s.X, s.Z, s.offset_s, d, use, rp);
      d[j] = -steps[j];
      const bool ok_m = model.residuals(s.X, s.Z, s.offset_s, d, use, rm);
      if (!ok_p || !ok_m) continue;
      for (std::size_t i = 0; i < rp.size(); ++i) J.at<double>(int(i), j) = (rp[i] - rm[i]) / (2 * steps[j]);
    }
  };
  const double zero[kParams] = {};
  if (!model.residuals(s.X, s.Z, s.offset_s, zero, use, r)) return;
  double cost = sum_squares(r);
  cv::Mat J;
  for (int iteration = 0; iteration < 50; ++iteration) {
    jacobian(J);
    const cv::Mat rv(int(r.size()), 1, CV_64F, r.data());
    const cv::Mat JtJ = J.t() * J, Jtr = J.t() * rv;
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      cv::Mat A = JtJ.clone();
      for (int j = 0; j < n; ++j) A.at<double>(j, j) += lambda * std::max(JtJ.at<double>(j, j), 1e-12);
      cv::Mat delta;
      cv::solve(A, -Jtr, delta, cv::DECOMP_CHOLESKY);
      double d[kParams] = {};
      for (int j = 0; j < n; ++j) d[j] = delta.at<double>(j);
      std::vector<double> trial;
      if (model.residuals(s.X, s.Z, s.offset_s, d, use, trial) && sum_squares(trial) < cost) {
        s.X = perturbed(s.X, d);
        s.Z = perturbed(s.Z, d + 6);
        s.offset_s += d[12];
        const double new_cost = sum_squares(trial);
        const bool converged = cost - new_cost < 1e-10 * cost;
        cost = new_cost;
        r = std::move(trial);
        lambda = std::max(lambda * 0.3, 1e-9);
        improved = true;
        if (converged) iteration = 1000;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  jacobian(J);
  const int dof = std::max(1, int(r.size()) - n);
  cv::Mat cov_n;
  cv::invert(J.t() * J, cov_n, cv::DECOMP_SVD);
  s.covariance = cv::Mat::zeros(kParams, kParams, CV_64F);
  cov_n.copyTo(s.covariance(cv::Rect(0, 0, n, n)));
  s.covariance *= cost / dof;
}

}  // namespace

RigCalibrationResult calibrate_rig(const std::vector<BoardView>& views_in, const tracking::PoseStream& tracker,
                                   int station, Nanos assumed_latency, const RigCalibrationOptions& o) {
  RigCalibrationResult out;
  out.assumed_latency = assumed_latency;
  out.views_given = int(views_in.size());
  const std::string where = "rig calibration: ";
  if (int(views_in.size()) < o.min_views)
    throw InputError(where + "the board was found in only " + std::to_string(views_in.size()) + " frames; at least " +
                     std::to_string(o.min_views) + " are needed (film the whole board from many angles)");
  const auto& samples = tracker.samples(station);
  if (samples.size() < 2)
    throw InputError(where + "the recording has no tracker poses for station " + std::to_string(station) +
                     "; check the tracker stream and the session's station");

  std::vector<BoardView> views = views_in;
  std::sort(views.begin(), views.end(), [](const BoardView& a, const BoardView& b) { return a.time < b.time; });

  // 1. Views whose corners disagree with a rigid board (blur, a misdetection).
  {
    std::vector<double> rms;
    for (const auto& v : views) rms.push_back(v.reprojection_rms_px);
    const double med = median(rms);
    std::vector<double> dev;
    for (double e : rms) dev.push_back(std::abs(e - med));
    out.median_view_rms_px = med;
    out.view_rms_threshold_px = std::max(o.view_rms_floor_px, med + 5 * 1.4826 * median(dev));
    std::vector<BoardView> kept;
    for (const auto& v : views)
      if (v.reprojection_rms_px <= out.view_rms_threshold_px) kept.push_back(v);
    out.views_rejected_pnp = int(views.size() - kept.size());
    views = std::move(kept);
  }
  if (int(views.size()) < o.min_views)
    throw InputError(where + "only " + std::to_string(views.size()) + " views have a consistent board pose; at least " +
                     std::to_string(o.min_views) + " are needed");
  for (const auto& v : views)
    out.rotation_range_deg = std::max(
        out.rotation_range_deg, rotation_angle_deg(views.front().T_camera_board.rotation, v.T_camera_board.rotation));
  if (out.rotation_range_deg < o.min_rotation_deg)
    throw InputError(where + "the camera turns only " + fmt(out.rotation_range_deg) +
                     " degrees over the recording; at least " + fmt(o.min_rotation_deg, 0) +
                     " are needed (tilt and turn it about all axes while filming the board)");
  if (out.rotation_range_deg < 30)
    out.warnings.push_back("the camera turns only " + fmt(out.rotation_range_deg) +
                           " degrees; 45 or more about all axes gives a better calibration");

  // 2. Time offset from the angular speeds.
  if (o.estimate_time_offset) {
    std::vector<Nanos> vt, tt;
    std::vector<glm::dquat> vr, tr;
    for (const auto& v : views) vt.push_back(v.time), vr.push_back(v.T_camera_board.rotation);
    for (const auto& s : samples) tt.push_back(s.time), tr.push_back(s.T_transmitter_sensor.rotation);
    // The window must hold a view on each side, whatever frames were skipped (--every).
    std::vector<double> spacing;
    for (std::size_t i = 1; i < vt.size(); ++i) spacing.push_back(double(vt[i] - vt[i - 1]));
    const Nanos video_span = std::max(o.time_offset.video_span, Nanos(2.1 * median(spacing)));
    const auto estimate = estimate_time_offset(angular_speed(vt, vr, video_span),
                                               angular_speed(tt, tr, o.time_offset.tracker_span), o.time_offset);
    out.correlation_offset = estimate.offset;
    out.peak_correlation = estimate.peak_correlation;
    out.correlation_at_zero = estimate.correlation_at_zero;
    if (estimate.peak_correlation < 0.5)
      out.warnings.push_back("the tracker's and the video's angular speeds correlate weakly (" +
                             fmt(estimate.peak_correlation, 2) + "); the time offset may be wrong");
    if (std::llabs(estimate.offset) > o.time_offset.max_offset - 2 * o.time_offset.step)
      out.warnings.push_back("the time offset sits at the edge of the search range; widen it");
  }

  // 3. Hand-eye on tracker samples paired with the camera interpolated at their time.
  CameraPath path;
  {
    std::vector<Nanos> spacing;
    for (const auto& v : views) {
      if (!path.times.empty()) spacing.push_back(v.time - path.times.back());
      path.times.push_back(v.time);
      path.T_board_camera.push_back(v.T_camera_board.inverse());
    }
    path.max_gap = Nanos(2.5 * median(std::vector<double>(spacing.begin(), spacing.end())));
  }
  std::vector<int> use;
  std::vector<Pose> sensor, board;
  const Nanos margin = 30'000'000;  // room for the refinement to move the offset
  for (std::size_t j = 0; j < samples.size(); ++j) {
    const Nanos t = samples[j].time - out.correlation_offset;
    const auto camera = path.at(t);
    if (!camera || !path.at(t - margin) || !path.at(t + margin)) continue;
    use.push_back(int(j));
    sensor.push_back(samples[j].T_transmitter_sensor);
    board.push_back(camera->inverse());
  }
  if (int(use.size()) < o.min_views)
    throw InputError(where + "only " + std::to_string(use.size()) +
                     " tracker samples fall between board views; record the tracker for the whole video");
  out.hand_eye = solve_hand_eye(sensor, board, o.hand_eye);

  FitState state{
      out.hand_eye.T_sensor_camera, out.hand_eye.T_transmitter_board, nanos_to_seconds(out.correlation_offset), {}};
  const RigModel model{&samples, &path, o.tracker_rotation_sigma_deg * kPi / 180.0, o.tracker_position_sigma_m};
  std::vector<double> r;
  if (o.refine) {
    // 4. Joint refinement, then once more without the samples it cannot explain.
    refine(model, use, state, o.estimate_time_offset);
    if (model.residuals(state.X, state.Z, state.offset_s, use, r)) {
      std::vector<double> e(use.size());
      for (std::size_t k = 0; k < use.size(); ++k)
        for (int a = 0; a < 6; ++a) e[k] += r[6 * k + std::size_t(a)] * r[6 * k + std::size_t(a)];
      const double scale = median(e) / 5.348;  // chi-square 6's median
      std::vector<int> kept;
      for (std::size_t k = 0; k < use.size(); ++k)
        if (e[k] <= o.residual_outlier_chi2 * scale) kept.push_back(use[k]);
      out.samples_rejected_residual = int(use.size() - kept.size());
      if (int(kept.size()) >= o.min_views && out.samples_rejected_residual > 0) {
        use = std::move(kept);
        refine(model, use, state, o.estimate_time_offset);
      }
    }
    out.sigma_rotation_deg = std::sqrt(state.covariance.at<double>(0, 0) + state.covariance.at<double>(1, 1) +
                                       state.covariance.at<double>(2, 2)) *
                             180.0 / kPi;
    out.sigma_translation_m = std::sqrt(state.covariance.at<double>(3, 3) + state.covariance.at<double>(4, 4) +
                                        state.covariance.at<double>(5, 5));
    out.sigma_time_offset_s = std::sqrt(state.covariance.at<double>(12, 12));
  }
  out.views_used = int(views.size());
  out.samples_used = int(use.size());
  out.time_offset = seconds_to_nanos(state.offset_s);

  if (model.residuals(state.X, state.Z, state.offset_s, use, r)) {
    double rot = 0, pos = 0;
    for (std::size_t k = 0; k < use.size(); ++k)
      for (int a = 0; a < 3; ++a) {
        rot += std::pow(r[6 * k + std::size_t(a)] * model.sigma_rotation_rad, 2);
        pos += std::pow(r[6 * k + 3 + std::size_t(a)] * model.sigma_position_m, 2);
      }
    out.rotation_rms_deg = std::sqrt(rot / double(use.size())) * 180.0 / kPi;
    out.translation_rms_m = std::sqrt(pos / double(use.size()));
  }
  out.rig.T_sensor_camera = state.X;
  out.rig.T_world_transmitter = o.T_world_board * state.Z.inverse();
  out.rig.latency = assumed_latency + out.time_offset;
  if (out.sigma_time_offset_s > 0.002)
    out.warnings.push_back("the time offset is uncertain (+-" + fmt(out.sigma_time_offset_s * 1e3) +
                           " ms); move the camera faster, with changes of speed");
  return out;
}

}  // namespace lumar::calib
