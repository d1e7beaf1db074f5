// The edge of tracking/: device units and Polhemus angles to metres and quaternions.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lumar/tracking/isotrak_ascii.h"
#include "lumar/tracking/pose_conversion.h"

namespace lumar::tracking {
namespace {

// R = Rz(az) Ry(el) Rx(roll) written out by hand (row-major r[row][col]).
glm::dmat3 polhemus_matrix_by_hand(double az_deg, double el_deg, double roll_deg) {
  const double a = az_deg * M_PI / 180, e = el_deg * M_PI / 180, r = roll_deg * M_PI / 180;
  const double ca = std::cos(a), sa = std::sin(a), ce = std::cos(e), se = std::sin(e), cr = std::cos(r),
               sr = std::sin(r);
  const double m[3][3] = {{ca * ce, ca * se * sr - sa * cr, ca * se * cr + sa * sr},
                          {sa * ce, sa * se * sr + ca * cr, sa * se * cr - ca * sr},
                          {-se, ce * sr, ce * cr}};
  glm::dmat3 out;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) out[col][row] = m[row][col];  // glm is column-major
  return out;
}

double max_abs_diff(const glm::dmat3& a, const glm::dmat3& b) {
  double d = 0;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) d = std::max(d, std::abs(a[c][r] - b[c][r]));
  return d;
}

TEST(PoseConversion, InchesAndCentimetresToMetres) {
  IsotrakRecord r;
  r.station = 2;
  r.position = glm::dvec3(10.0, -20.0, 30.5);
  r.attitude_deg = glm::dvec3(0.0);
  OutputFormat inches;
  const auto s = to_pose_sample(r, inches, 123);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->time, 123);
  EXPECT_EQ(s->station, 2);
  EXPECT_NEAR(s->T_transmitter_sensor.translation.x, 0.254, 1e-15);
  EXPECT_NEAR(s->T_transmitter_sensor.translation.y, -0.508, 1e-15);
  EXPECT_NEAR(s->T_transmitter_sensor.translation.z, 0.7747, 1e-15);
  OutputFormat cm;
  cm.centimetres = true;
  EXPECT_NEAR(to_pose_sample(r, cm, 0)->T_transmitter_sensor.translation.z, 0.305, 1e-15);
}

TEST(PoseConversion, ParsedAttitudeMatchesHandBuiltMatrix) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> az(-180.0, 180.0), el(-90.0, 90.0);
  const OutputFormat f;
  AsciiRecordParser parser(f);
  for (int i = 0; i < 1000; ++i) {
    IsotrakRecord r;
    r.position = glm::dvec3(1.0, 2.0, 3.0);
    r.attitude_deg = glm::dvec3(az(rng), el(rng), az(rng));
    parser.push(ByteChunk{0, [&] {
                            const std::string s = encode_ascii_record(r, f);
                            return std::vector<std::uint8_t>(s.begin(), s.end());
                          }()});
  }
  double worst = 0;
  int n = 0;
  while (auto rec = parser.next()) {
    const glm::dvec3 a = *rec->record.attitude_deg;
    const auto s = to_pose_sample(rec->record, f, 0);
    ASSERT_TRUE(s.has_value());
    EXPECT_NEAR(glm::length(s->T_transmitter_sensor.rotation), 1.0, 1e-12);
    worst = std::max(
        worst, max_abs_diff(glm::mat3_cast(s->T_transmitter_sensor.rotation), polhemus_matrix_by_hand(a.x, a.y, a.z)));
    ++n;
  }
  EXPECT_EQ(n, 1000);
  EXPECT_LE(worst, 1e-9);
  std::printf("attitude -> quaternion vs hand-built Rz Ry Rx: max element difference %.2e\n", worst);
}

TEST(PoseConversion, PrefersTheQuaternionItemAndRenormalisesIt) {
  IsotrakRecord r;
  r.position = glm::dvec3(0.0);
  r.attitude_deg = glm::dvec3(90.0, 0.0, 0.0);          // disagrees on purpose
  r.quaternion = glm::dquat(0.7071, 0.7071, 0.0, 0.0);  // 90 deg about x, 4 decimals
  const auto s = to_pose_sample(r, OutputFormat{}, 0);
  ASSERT_TRUE(s.has_value());
  const glm::dquat q = s->T_transmitter_sensor.rotation;
  EXPECT_NEAR(glm::length(q), 1.0, 1e-15);
  EXPECT_NEAR(q.w, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(q.x, std::sqrt(0.5), 1e-15);
}

TEST(PoseConversion, DropsIncompleteOrNonFiniteRecords) {
  const OutputFormat f;
  IsotrakRecord good;
  good.position = glm::dvec3(1.0);
  good.attitude_deg = glm::dvec3(1.0);
  ASSERT_TRUE(to_pose_sample(good, f, 0).has_value());
  IsotrakRecord r = good;
  r.position.reset();
  EXPECT_FALSE(to_pose_sample(r, f, 0));
  r = good;
  r.attitude_deg.reset();
  EXPECT_FALSE(to_pose_sample(r, f, 0));
  r = good;
  r.position->y = NAN;
  EXPECT_FALSE(to_pose_sample(r, f, 0));
  r = good;
  r.attitude_deg->z = INFINITY;
  EXPECT_FALSE(to_pose_sample(r, f, 0));
  r = good;
  r.quaternion = glm::dquat(0.5, 0.0, 0.0, 0.0);  // norm 0.5: garbled, not rounding
  EXPECT_FALSE(to_pose_sample(r, f, 0));
  r.quaternion = glm::dquat(NAN, 0.0, 0.0, 0.0);
  EXPECT_FALSE(to_pose_sample(r, f, 0));
}

}  // namespace
}  // namespace lumar::tracking
