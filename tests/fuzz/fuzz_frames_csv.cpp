// A recording's frames.csv (RecordingReader): any bytes give frames or one InputError,
// and accepted frames are in order: indices and times increase, times are not negative,
// segments run from 0 without gaps.
#include "fuzz_input.h"
#include "lumar/base/error.h"
#include "lumar/capture/recording_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lumar;
  static const std::string session =
      R"({"format": "lumar-recording", "version": 1, "complete": true,)"
      R"( "video": {"codec": "mjpeg", "frames_per_segment": 4, "fps": 30, "width": 64, "height": 48}})";
  const auto dir = fuzz::scratch() / "rec";
  fuzz::write_file(dir / "session.json", session.data(), session.size());
  fuzz::input_file(data, size, "rec/frames.csv");
  try {
    const capture::RecordingReader reader(dir);
    const auto& frames = reader.frames();
    for (std::size_t i = 0; i < frames.size(); ++i) {
      FUZZ_CHECK(frames[i].time >= 0 && frames[i].index >= 0);
      FUZZ_CHECK(frames[i].segment_frame >= 0 && frames[i].segment_frame < 4);
      if (i == 0) {
        FUZZ_CHECK(frames[i].segment == 0 && frames[i].segment_frame == 0);
      } else {
        FUZZ_CHECK(frames[i].index > frames[i - 1].index && frames[i].time > frames[i - 1].time);
        FUZZ_CHECK(frames[i].segment == frames[i - 1].segment || frames[i].segment == frames[i - 1].segment + 1);
      }
    }
  } catch (const InputError&) {
  }
  return 0;
}
