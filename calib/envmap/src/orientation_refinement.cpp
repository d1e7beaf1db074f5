#include "lumar/envmap/orientation_refinement.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"

namespace lumar::calib {

FrameFeatures extract_frame_features(const cv::Mat& image, const CameraIntrinsics& camera,
                                     const CameraResponse& response, const FeatureSettings& settings) {
  if (image.type() != CV_8UC3 || image.cols != camera.width || image.rows != camera.height)
    throw InputError("envmap: frame size or type does not match the camera calibration");
  // Log luminance: descriptors compare intensities, so a change of exposure (a scale in
  // linear light) becomes an offset they do not see.
  std::array<float, 256> lut[3];
  for (int c = 0; c < 3; ++c)
    for (int v = 0; v < 256; ++v) lut[c][v] = std::max(response(c, v), 1e-6f);
  cv::Mat grey(image.size(), CV_8UC1), bad(image.size(), CV_8UC1);
  std::vector<float> logs(std::size_t(image.total()));
  for (int y = 0; y < image.rows; ++y) {
    const cv::Vec3b* p = image.ptr<cv::Vec3b>(y);
    for (int x = 0; x < image.cols; ++x) {
      const float lum = 0.114f * lut[0][p[x][0]] + 0.587f * lut[1][p[x][1]] + 0.299f * lut[2][p[x][2]];
      logs[std::size_t(y) * image.cols + x] = std::log2(std::max(lum, 1e-6f));
      const int vmax = std::max({p[x][0], p[x][1], p[x][2]});
      bad.at<uchar>(y, x) = (vmax >= settings.saturated_value || vmax <= settings.dark_value) ? 255 : 0;
    }
  }
  std::vector<float> sorted = logs;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const float median = sorted[sorted.size() / 2];
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      grey.at<uchar>(y, x) = cv::saturate_cast<uchar>(128.f + 16.f * (logs[std::size_t(y) * image.cols + x] - median));
  cv::Mat mask;
  cv::dilate(bad, mask, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(17, 17)));
  cv::bitwise_not(mask, mask);

  auto orb = cv::ORB::create(settings.max_features, 1.2f, 2, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, 10);
  std::vector<cv::KeyPoint> keypoints;
  FrameFeatures out;
  orb->detectAndCompute(grey, mask, keypoints, out.descriptors);
  if (keypoints.empty()) return out;
  // Sub-pixel corner positions: the rotation error we aim for is about a pixel's tenth.
  std::vector<cv::Point2f> points;
  for (const auto& k : keypoints) points.push_back(k.pt);
  cv::cornerSubPix(grey, points, cv::Size(3, 3), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.01));
  std::vector<cv::Point2d> pixels(points.begin(), points.end()), normalized;
  cv::undistortPoints(pixels, normalized, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients(),
                      cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 40, 1e-12));
  out.bearings.reserve(normalized.size());
  for (const auto& n : normalized) out.bearings.push_back(glm::normalize(glm::dvec3(n.x, n.y, 1.0)));
  return out;
}

namespace {

struct Match {
  int i, j;
  glm::dvec3 a, b;  // bearing in frame i, bearing in frame j
};

double angle_between(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

// Rotation R minimising sum |a_k - R b_k|^2 (Kabsch).
glm::dmat3 fit_rotation(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b) {
  cv::Matx33d M = cv::Matx33d::zeros();
  for (std::size_t k = 0; k < a.size(); ++k)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) M(r, c) += a[k][r] * b[k][c];
  cv::SVD svd(M);
  cv::Mat U = svd.u, Vt = svd.vt;
  cv::Mat D = cv::Mat::eye(3, 3, CV_64F);
  if (cv::determinant(U * Vt) < 0) D.at<double>(2, 2) = -1;
  const cv::Mat R = U * D * Vt;
  glm::dmat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[c][r] = R.at<double>(r, c);
  return out;
}

// Inlier matches between frames i and j, or none if the pair does not hold together.
std::vector<Match> match_pair(int i, int j, const FrameFeatures& fi, const FrameFeatures& fj, const glm::dquat& Ri,
                              const glm::dquat& Rj, const RefinementSettings& s) {
  std::vector<Match> out;
  if (fi.descriptors.empty() || fj.descriptors.empty()) return out;
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(fi.descriptors, fj.descriptors, knn, 2);
  const glm::dmat3 Rij = glm::mat3_cast(glm::conjugate(Ri) * Rj);  // frame j -> frame i, tracker
  const double gate = glm::radians(s.gate_deg);
  std::vector<glm::dvec3> a, b;
  for (const auto& m : knn) {
    if (m.empty()) continue;
    if (m.size() == 2 && m[0].distance > s.ratio * m[1].distance) continue;
    const glm::dvec3& ba = fi.bearings[m[0].queryIdx];
    const glm::dvec3& bb = fj.bearings[m[0].trainIdx];
    if (angle_between(ba, Rij * bb) > gate) continue;
    a.push_back(ba), b.push_back(bb);
  }
  if (int(a.size()) < s.min_matches) return out;
  // Fit the pair's relative rotation, keep what agrees with it, and fit again.
  glm::dmat3 R = fit_rotation(a, b);
  const double thresholds[2] = {std::max(glm::radians(1.0), 3 * glm::radians(s.inlier_deg)),
                                glm::radians(s.inlier_deg)};
  for (double t : thresholds) {
    std::vector<glm::dvec3> a2, b2;
    for (std::size_t k = 0; k < a.size(); ++k)
      if (angle_between(a[k], R * b[k]) < t) a2.push_back(a[k]), b2.push_back(b[k]);
    if (int(a2.size()) < s.min_matches) return out;
    R = fit_rotation(a2, b2);
    a.swap(a2), b.swap(b2);
  }
  for (std::size_t k = 0; k < a.size(); ++k) out.push_back({i, j, a[k], b[k]});
  return out;
}

glm::dmat3 skew(const glm::dvec3& v) {
  // glm is column-major: skew(v) * x = cross(v, x).
  return glm::dmat3(glm::dvec3(0, v.z, -v.y), glm::dvec3(-v.z, 0, v.x), glm::dvec3(v.y, -v.x, 0));
}

double rms_residual_deg(const std::vector<Match>& matches, const std::vector<glm::dquat>& R) {
  if (matches.empty()) return 0;
  double sum = 0;
  for (const auto& m : matches) {
    const double a = angle_between(R[m.i] * m.a, R[m.j] * m.b);
    sum += a * a;
  }
  return glm::degrees(std::sqrt(sum / matches.size()));
}

}  // namespace

RefinementResult refine_orientations(const std::vector<FrameFeatures>& features, const std::vector<glm::dquat>& tracker,
                                     const RefinementSettings& s, const std::vector<int>& groups_in) {
  if (features.size() != tracker.size()) throw InputError("envmap: refinement needs one tracker rotation per frame");
  if (!groups_in.empty() && groups_in.size() != features.size())
    throw InputError("envmap: refinement needs one group per frame (or none)");
  const int n = int(features.size());
  RefinementResult result;
  result.rotations = tracker;
  result.correction_deg.assign(n, 0.0);
  if (n < 2) {
    result.unmatched_frames = n;
    return result;
  }
  // Frames of one group (a bracket taken standing still) share one rotation.
  std::vector<int> group(n);
  int groups = 0;
  {
    std::map<int, int> ids;
    for (int f = 0; f < n; ++f) {
      const int key = groups_in.empty() ? f : groups_in[f];
      auto [it, inserted] = ids.emplace(key, groups);
      if (inserted) ++groups;
      group[f] = it->second;
    }
  }
  std::vector<std::vector<int>> members(groups);
  for (int f = 0; f < n; ++f) members[group[f]].push_back(f);
  // Start each group at the mean of its frames' tracker rotations.
  std::vector<glm::dquat> R(groups);
  for (int g = 0; g < groups; ++g) {
    glm::dquat q = tracker[members[g][0]];
    for (int k = 0; k < 3; ++k) {
      glm::dvec3 mean(0.0);
      for (int f : members[g]) mean += rotation_log(tracker[f] * glm::conjugate(q));
      q = glm::normalize(rotation_exp(mean / double(members[g].size())) * q);
    }
    R[g] = q;
  }

  // Candidate pairs: frames of different groups whose optical axes are close enough.
  std::vector<std::pair<int, int>> candidates;
  const double cos_max = std::cos(glm::radians(s.pair_max_angle_deg));
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      if (group[i] == group[j]) continue;
      const glm::dvec3 zi = R[group[i]] * glm::dvec3(0, 0, 1), zj = R[group[j]] * glm::dvec3(0, 0, 1);
      if (glm::dot(zi, zj) >= cos_max) candidates.emplace_back(i, j);
    }
  std::vector<std::vector<Match>> per_pair(candidates.size());
  tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t k) {
    const auto [i, j] = candidates[k];
    per_pair[k] = match_pair(group[i], group[j], features[i], features[j], R[group[i]], R[group[j]], s);
  });
  std::vector<Match> matches;
  std::vector<int> matched(groups, 0);
  for (const auto& p : per_pair) {
    if (p.empty()) continue;
    ++result.pairs;
    matched[p.front().i] = matched[p.front().j] = 1;
    matches.insert(matches.end(), p.begin(), p.end());
  }
  result.matches = int(matches.size());
  for (int f = 0; f < n; ++f) result.unmatched_frames += matched[group[f]] == 0;
  result.residual_before_deg = rms_residual_deg(matches, R);
  if (matches.empty()) return result;

  // Gauss-Newton on the left perturbations R_g <- exp(d_g) R_g.
  const double sigma_m = glm::radians(s.match_noise_deg);
  const double w_prior = 1.0 / std::pow(glm::radians(s.tracker_noise_deg) / std::sqrt(3.0), 2);
  const double huber = 2.0 * sigma_m;
  const int dim = 3 * groups;
  for (int iter = 0; iter < s.iterations; ++iter) {
    cv::Mat H = cv::Mat::zeros(dim, dim, CV_64F), g = cv::Mat::zeros(dim, 1, CV_64F);
    auto add_block = [&](int bi, int bj, const glm::dmat3& M) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) H.at<double>(3 * bi + r, 3 * bj + c) += M[c][r];
    };
    auto add_grad = [&](int bi, const glm::dvec3& v) {
      for (int r = 0; r < 3; ++r) g.at<double>(3 * bi + r) += v[r];
    };
    for (const auto& m : matches) {
      const glm::dvec3 wa = R[m.i] * m.a, wb = R[m.j] * m.b;
      const glm::dvec3 r = wa - wb;
      const double norm = glm::length(r);
      const double w = (norm <= huber ? 1.0 : huber / norm) / (sigma_m * sigma_m);
      const glm::dmat3 Ji = -skew(wa), Jj = skew(wb);
      const glm::dmat3 JiT = glm::transpose(Ji), JjT = glm::transpose(Jj);
      add_block(m.i, m.i, w * JiT * Ji);
      add_block(m.j, m.j, w * JjT * Jj);
      add_block(m.i, m.j, w * JiT * Jj);
      add_block(m.j, m.i, w * JjT * Ji);
      add_grad(m.i, w * (JiT * r));
      add_grad(m.j, w * (JjT * r));
    }
    for (int f = 0; f < n; ++f) {
      const glm::dvec3 rp = rotation_log(R[group[f]] * glm::conjugate(tracker[f]));
      add_block(group[f], group[f], glm::dmat3(w_prior));
      add_grad(group[f], w_prior * rp);
    }
    cv::Mat delta;
    if (!cv::solve(H, -g, delta, cv::DECOMP_CHOLESKY)) break;
    double max_step = 0;
    for (int k = 0; k < groups; ++k) {
      const glm::dvec3 d(delta.at<double>(3 * k), delta.at<double>(3 * k + 1), delta.at<double>(3 * k + 2));
      R[k] = glm::normalize(rotation_exp(d) * R[k]);
      max_step = std::max(max_step, glm::length(d));
    }
    if (max_step < 1e-9) break;
  }
  // Gauge: the images fix only relative rotations; put the sweep's mean rotation back
  // on the tracker's (Karcher mean of the differences over all frames).
  for (int k = 0; k < 4; ++k) {
    glm::dvec3 mean(0.0);
    for (int f = 0; f < n; ++f) mean += rotation_log(tracker[f] * glm::conjugate(R[group[f]]));
    const glm::dquat fix = rotation_exp(mean / double(n));
    for (auto& q : R) q = glm::normalize(fix * q);
  }
  for (int f = 0; f < n; ++f) {
    result.rotations[f] = R[group[f]];
    result.correction_deg[f] = rotation_angle_deg(R[group[f]], tracker[f]);
  }
  result.residual_after_deg = rms_residual_deg(matches, R);
  return result;
}

}  // namespace lumar::calib
