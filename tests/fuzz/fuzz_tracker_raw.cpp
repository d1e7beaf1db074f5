// tracker.raw's chunk reader (parse_tracker_chunks): every byte is either in a whole
// chunk or counted as ignored (a torn tail among them), and the chunks it finds, written again, read back the
// same with nothing ignored.
#include "fuzz_input.h"
#include "lumar/capture/recording_format.h"
#include "lumar/capture/tracker_raw.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lumar;
  std::size_t ignored = 0, torn = 0;
  const auto chunks = capture::parse_tracker_chunks({reinterpret_cast<const char*>(data), size}, &ignored, &torn);
  FUZZ_CHECK(torn <= ignored);
  std::size_t in_chunks = 0;
  std::string again;
  for (const auto& c : chunks) {
    in_chunks += capture::kTrackerChunkHeaderBytes + c.bytes.size();
    capture::append_tracker_chunk(again, c);
  }
  FUZZ_CHECK(in_chunks + ignored == size);
  std::size_t ignored_again = 1;
  const auto reread = capture::parse_tracker_chunks(again, &ignored_again);
  FUZZ_CHECK(ignored_again == 0 && reread.size() == chunks.size());
  for (std::size_t i = 0; i < chunks.size(); ++i)
    FUZZ_CHECK(reread[i].arrival == chunks[i].arrival && reread[i].bytes == chunks[i].bytes);
  return 0;
}
