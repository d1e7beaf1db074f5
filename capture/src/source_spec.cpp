#include "lumar/capture/source_spec.h"

#include <memory>

#include "lumar/capture/image_sequence_source.h"
#include "lumar/capture/recording_reader.h"
#include "lumar/capture/recording_source.h"
#include "lumar/capture/video_file_source.h"

namespace lumar::capture {

OpenedSource open_frame_source(const std::string& spec, const SourceOptions& options) {
  const std::size_t colon = spec.find(':');
  const std::string kind = colon == std::string::npos ? "" : spec.substr(0, colon);
  const std::string path = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (kind.empty() || path.empty())
    throw InputError("--source '" + spec +
                     "' is not a source; use video:FILE, images:DIR_OR_GLOB, v4l2:/dev/videoN or recording:DIR");
  if (kind == "video") return {std::make_unique<VideoFileSource>(path), false};
  if (kind == "images")
    return {std::make_unique<ImageSequenceSource>(ImageSequenceSettings{path, options.timestamps, options.fps}), false};
  if (kind == "recording") {
    // Played as a camera, it says its session's shutter time, as a camera its exposure time.
    const RecordingReader recording(path);
    return {std::make_unique<RecordingSource>(recording, seconds_to_nanos(recording.session().radiometry.shutter_s)),
            false};
  }
  if (kind == "v4l2") {
    V4l2Settings s = options.v4l2;
    s.path = path;
    return {std::make_unique<V4l2Source>(s), true};
  }
  throw InputError("--source '" + spec + "': unknown kind '" + kind + "'; use video:, images:, v4l2: or recording:");
}

}  // namespace lumar::capture
