#pragma once
// A sweep given as a folder of images with a poses CSV (`lumar envmap --images`), and
// the writer of that form (`lumar envmap --recording ... --export-images DIR`).
//
// Poses CSV: a header naming the columns, then one row per image, in any order:
//   file,qw,qx,qy,qz[,x,y,z][,exposure][,station]
//   frame-000000.png,0.92387953,0,0.38268343,0,0,1.5,0,0.25,0
// - file: the image, relative to the images' folder (the folder given, or the glob's).
// - qw,qx,qy,qz: R_world_camera, a unit quaternion: OpenCV camera axes (x right, y down,
//   z forward) to the world (right-handed, +Y up), as in recordings' truth.csv.
// - x,y,z: where the camera was (world, metres); the map's capture position is their
//   mean (without them: 0, 0, 0).
// - exposure: video linear value per unit radiance (default 1).
// - station: frames with the same station were taken standing still (e.g. a bracket)
//   and are refined as one rotation.
// Every image needs exactly one row and every row one image.
#include <string>

#include "lumar/pipeline/envmap_sweep.h"

namespace lumar::pipeline {

struct ImagesInputOptions {
  std::string images;    // folder or glob
  std::string poses;     // the CSV above
  std::string camera;    // calibration (OpenCV YAML) of the camera that took them
  std::string response;  // lumar-camera-response JSON (empty: sRGB)
  double vignetting_a = 0, vignetting_b = 0;
  double tracker_noise_deg = 0.75;  // how far the poses' rotations may be off (the refinement's prior)
};

// Reads the CSV, lists the images and checks that they match. InputError, one line,
// for: no images, a missing image, a row for a file outside the images, an image
// without a row, a bad header or number, a quaternion that is not unit length or not
// finite, a non-positive exposure, an image of another size than the calibration.
SweepInput images_sweep_input(const ImagesInputOptions& options, int width);

// Writes every frame of `input` as DIR/frame-NNNNNN.png, DIR/poses.csv with its tracked
// rotations, capture position, exposures and stations, and DIR/camera.yml. DIR must not
// exist; it appears complete or not at all.
void export_sweep_images(const SweepInput& input, const std::string& dir);

}  // namespace lumar::pipeline
