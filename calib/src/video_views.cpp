#include "lumar/calib/video_views.h"

#include "lumar/base/error.h"

namespace lumar::calib {

std::vector<NamedImage> sample_frames(capture::FrameSource& source, int every, int max_frames) {
  if (every < 1) throw InputError("--every: must be 1 or more");
  std::vector<NamedImage> out;
  capture::Frame frame;
  for (int k = 0; int(out.size()) < max_frames && source.read(frame); ++k)
    if (k % every == 0) out.push_back({source.describe() + "#" + std::to_string(frame.index), frame.image.clone()});
  if (out.empty()) throw InputError(source.describe() + ": delivered no frames");
  return out;
}

}  // namespace lumar::calib
