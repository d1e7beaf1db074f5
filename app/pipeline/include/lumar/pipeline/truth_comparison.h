#pragma once
// A recording's composite against its truth/ (docs/ground_truth.md): replayed with the
// true poses, so that registration is not part of the measure, and every frame measured
// by CompositeErrorMeter. What `lumar regress` and the composite benchmark report.
#include <filesystem>
#include <functional>
#include <optional>

#include "lumar/pipeline/composite_error.h"
#include "lumar/pipeline/replay_overlay.h"

namespace lumar::pipeline {

struct TruthComparison {
  CompositeError error;
  double ms_per_frame = 0;               // the overlay's stages (decode to read-back), mean per frame after the first
  std::optional<QualityChoice> quality;  // what settings.auto_quality chose, if asked
};

// Each composite frame with its truth and the truth's object mask, undistorted like it
// (for pictures).
using TruthFrameVisitor = std::function<void(const OverlayFrame& frame, const cv::Mat& truth, const cv::Mat& mask)>;

// nullopt when the recording has no truth/; the frames measured are those with a
// truth/frame-*.png (synth --truth-frames). `settings.poses` is set to the truth's.
// InputError for a truth/ without frames, and for a missing, unreadable or wrongly
// sized image of a frame that has truth.
std::optional<TruthComparison> compare_with_truth(const std::filesystem::path& recording,
                                                  ReplayOverlaySettings settings, const TruthFrameVisitor& visit = {});

}  // namespace lumar::pipeline
