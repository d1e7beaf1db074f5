// lumar record: frames from any source and a tracker's raw stream into a recording
// (pipeline/live_record.h).
#include <memory>

#include "commands.h"
#include "lumar/pipeline/live_record.h"

namespace lumar::app {

void register_record(CLI::App& app) {
  auto o = std::make_shared<pipeline::RecordOptions>();
  auto* cmd = app.add_subcommand("record", "Record frames from a source and a tracker's raw stream into a recording");
  cmd->add_option("--source", o->in.source, "video:FILE, images:DIR_OR_GLOB, v4l2:/dev/videoN or recording:DIR")
      ->required();
  cmd->add_option("--out", o->out, "Recording directory to create (must not exist)")->required();
  add_live_input_options(cmd, o->in);
  cmd->add_option("--codec", o->codec, "Video codec: mjpeg (near-lossless) or ffv1 (lossless)")
      ->check(CLI::IsMember({"mjpeg", "ffv1"}))
      ->capture_default_str();
  cmd->add_option("--quality", o->quality, "MJPEG quality")->check(CLI::Range(50, 100))->capture_default_str();
  cmd->add_option("--segment-seconds", o->segment_seconds,
                  "Video segment length: at most this much video is lost in a crash")
      ->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "Stop after this many seconds (0: at the end of the source or Ctrl-C)")
      ->capture_default_str();
  cmd->add_option("--max-frames", o->max_frames, "Stop after this many frames (0: no limit)")->capture_default_str();
  cmd->add_option("--min-free-mb", o->min_free_mb, "Stop cleanly when the disk has less free space than this")
      ->capture_default_str();
  add_action(cmd, [o] { pipeline::record_live(*o); });
}

}  // namespace lumar::app
