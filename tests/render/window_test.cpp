// The GLFW window. These need an X server: ctest runs them under xvfb-run (render.window).
// Without a display they fail, by design: a skipped window test would hide a broken setup.
#include <gtest/gtest.h>

#include "lumar/render/platform/context.h"
#include "lumar/render/renderer.h"
#include "render_test_util.h"

namespace lumar::test {
namespace {

cv::Mat test_pattern(int width, int height) {
  cv::Mat image(height, width, CV_8UC3);
  cv::RNG rng(3);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c)
      image.at<cv::Vec3b>(r, c) = cv::Vec3b(uchar(c), uchar(r), uchar(rng.uniform(0, 256)));
  return image;
}

int max_abs_diff(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  double worst = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
  return int(worst);
}

TEST(WindowContext, PresentInCornerShowsTheImageExactly) {
  gl::WindowContext window(256, 200, "lumar window test");
  std::printf("window renderer: %s\n", window.renderer_name().c_str());
  EXPECT_FALSE(window.should_close());
  // Asymmetric, so a flip or a channel swap would show.
  const cv::Mat image = test_pattern(256, 200);
  for (int frame = 0; frame < 2; ++frame) {  // the second frame checks that re-presenting works
    const cv::Mat shown = frame == 0 ? image : cv::Mat(cv::Scalar::all(255) - image);
    cv::Mat back;
    window.present_in_corner(shown, [&] { back = window.read_back_buffer(); });
    window.poll_events();
    EXPECT_EQ(max_abs_diff(back, shown), 0);  // what was drawn before the swap
    const cv::Mat front = window.read_front_buffer();
    ASSERT_EQ(front.size(), shown.size());
    const int worst = max_abs_diff(front, shown);
    std::printf("frame %d: max |diff| %d levels\n", frame, worst);
    EXPECT_LE(worst, 1);
  }
  // A smaller image sits at its own size in the top-left corner; the rest is cleared.
  window.present_in_corner(cv::Mat(50, 70, CV_8UC3, cv::Scalar(10, 200, 90)), {});
  const cv::Mat front = window.read_front_buffer();
  EXPECT_LE(max_abs_diff(front(cv::Rect(0, 0, 70, 50)), cv::Mat(50, 70, CV_8UC3, cv::Scalar(10, 200, 90))), 1);
  EXPECT_LE(max_abs_diff(front(cv::Rect(70, 50, 186, 150)), cv::Mat(150, 186, CV_8UC3, cv::Scalar(33, 31, 31))), 1);
}

TEST(WindowContext, RendererDrawsInTheWindowsContext) {
  gl::WindowContext window(160, 120, "lumar renderer in a window");
  gl::Renderer renderer(make_camera(160, 120, 150, 150, 80, 60));
  const cv::Mat video = test_pattern(160, 120);
  const cv::Mat out = renderer.render_overlay(video, Pose{}, 1.0);
  EXPECT_EQ(max_abs_diff(out, video), 0);  // no objects: the video round-trips
  window.present_in_corner(out, {});
  EXPECT_LE(max_abs_diff(window.read_front_buffer(), video), 1);
}

}  // namespace
}  // namespace lumar::test
