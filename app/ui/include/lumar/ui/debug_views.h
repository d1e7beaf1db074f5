#pragma once
// What the composite is made from, drawn over it: the proxy as a wireframe, the shadow
// receivers coloured by their attenuation, the emitter patches' sample points, and the
// irradiance volume's probes coloured by the light they hold. Drawn with OpenCV on a copy
// of the composite, in the output camera's pixels.
#include <opencv2/core.hpp>

#include "lumar/base/pose.h"
#include "lumar/render/compositor.h"

namespace lumar::ui {

struct DebugViews {
  bool proxy_wireframe = false;
  bool receivers = false;  // green: lit, red: fully shadowed
  bool emitters = false;   // yellow, larger where a sample carries more light
  bool probes = false;     // grey levels: the irradiance from above, relative to the brightest
  bool any() const { return proxy_wireframe || receivers || emitters || probes; }
};

// `composite` with the chosen views drawn over it, seen from T_world_camera.
cv::Mat draw_debug_views(const cv::Mat& composite, const Compositor& compositor, const Pose& T_world_camera,
                         const DebugViews& views);

}  // namespace lumar::ui
