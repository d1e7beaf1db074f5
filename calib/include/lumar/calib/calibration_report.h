#pragma once
// What `lumar calibrate` leaves behind: the calibration YAML with its statistics, and
// a picture of where the board's corners fell on the sensor.
#include <filesystem>

#include "lumar/calib/robust_calibration.h"

namespace lumar::calib {

// OpenCV's sample keys (camera_file.h; load_camera_file reads the file) plus the
// statistics of `result` (docs/formats.md, "Calibration report"). Atomic write.
void save_calibration_report(const std::filesystem::path& path, const RobustCalibrationResult& result,
                             cv::Size board_inner_corners, double square_size_m);

// PNG (or any cv::imwrite format, by extension) of the sensor: the coverage grid's
// occupied cells shaded and its empty ones hatched in red, each kept view's corners as
// dots of its own colour, rejected views' corners as grey crosses; below it a legend and
// the parts of the sensor that still want views. Atomic write.
void write_coverage_image(const std::filesystem::path& path, const BoardViews& views,
                          const RobustCalibrationResult& result, const RobustCalibrationOptions& options = {});

// The kept view the lens bends most, as recorded and undistorted with the result side
// by side, each row of board corners on the undistorted half with the straight line
// through its ends: to judge the calibration by eye. Atomic write.
void write_undistorted_preview(const std::filesystem::path& path, const std::vector<NamedImage>& images,
                               const BoardViews& views, const RobustCalibrationResult& result);

}  // namespace lumar::calib
