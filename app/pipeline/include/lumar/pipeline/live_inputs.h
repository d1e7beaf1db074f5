#pragma once
// The inputs of the live commands (`lumar record`, `lumar overlay --source`): a frame
// source given as a spec (capture/source_spec.h) and a tracker on a serial port, with
// the options they share, and the session.json that describes them.
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "lumar/base/camera.h"
#include "lumar/capture/frame_source.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/tracking/rig.h"
#include "lumar/tracking/tracker_driver.h"

namespace lumar::pipeline {

struct LiveInputOptions {
  std::string source;             // video:FILE | images:DIR_OR_GLOB | v4l2:/dev/videoN | recording:DIR
  std::string timestamps;         // images: file,time_ns table
  double images_fps = 0;          // images: fixed rate
  int width = 640, height = 480;  // v4l2
  double camera_fps = 30;         // v4l2
  std::string pixel_format;       // v4l2: YUYV, MJPG (empty: YUYV, then MJPG, then libv4l2's BGR)
  int exposure_100us = -1, gain = -1;
  bool auto_exposure = false;  // v4l2: leave auto exposure on
  std::string tracker;         // serial:/dev/ttyUSB0 (empty: no tracker)
  std::string tracker_model = "isotrak2";
  int baud = 115200;
  double latency_ms = 0;    // device latency, subtracted from pose times
  std::string camera_file;  // OpenCV YAML intrinsics (empty: nominal pinhole)
};

struct LiveSource {
  std::unique_ptr<capture::FrameSource> source;  // CLOCK_MONOTONIC times (files are played in real time)
  bool camera = false;
};
LiveSource open_live_source(const LiveInputOptions& o);

// The recording behind a `recording:DIR` source given without --tracker: it brings its
// own poses (its tracker stream, as a replay decodes it). nullptr otherwise.
std::shared_ptr<const capture::RecordingReplay> recorded_poses_of(const LiveInputOptions& o);

// The tracker driver for --tracker (nullptr when none was given); nothing is opened
// before start(). InputError for a port that does not exist or bad settings.
std::unique_ptr<tracking::TrackerDriver> make_tracker_driver(const LiveInputOptions& o,
                                                             tracking::TrackerDriver::ByteObserver on_bytes);

// Intrinsics from --camera, or a nominal pinhole (focal length = width, no distortion)
// for a frame size, flagged as such in the session.
CameraIntrinsics live_camera(const LiveInputOptions& o, int width, int height);

// The rig to pair frames with poses: the "rig" of a session.json, or (empty path) the
// identity with --latency-ms. InputError naming the file when it cannot be read.
tracking::Rig live_rig(const std::string& session_json, double latency_ms);

// A source's shutter time as a session's radiometry.shutter_s, held to its 1 s bound
// (0: the source does not say).
double source_shutter_s(const capture::FrameSource& source);

// session.json content for a recording of these inputs (camera, tracker, rig, and the
// shutter time, source_shutter_s).
nlohmann::json live_session(const LiveInputOptions& o, const CameraIntrinsics& camera,
                            const tracking::TrackerDriver* driver, double shutter_s);

}  // namespace lumar::pipeline
