// lumar tracker decode: raw tracker bytes (a capture of the serial line, or a
// recording's tracker.raw) -> CSV of poses, with a summary line on stderr.
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/base/output_file.h"
#include "lumar/capture/recording_format.h"
#include "lumar/capture/tracker_raw.h"
#include "lumar/tracking/tracker_decode.h"

namespace lumar::app {

namespace {

struct DecodeOptions {
  std::string file;
  std::string device = "isotrak2";
  bool binary = false;
  std::string units = "in";
  std::string list = "2,4,1";
  std::string out;
};

bool has_chunk_magic(const std::string& data) {
  if (data.size() < 4) return false;
  std::uint32_t magic = 0;
  for (int i = 0; i < 4; ++i) magic |= std::uint32_t(std::uint8_t(data[i])) << (8 * i);
  return magic == capture::kTrackerChunkMagic;
}

void run_decode(const DecodeOptions& o) {
  tracking::TrackerFormat format;
  try {
    tracking::OutputFormat output;
    output.output_list = tracking::parse_output_list(o.list);
    if (o.units != "in" && o.units != "cm")
      throw InputError("units '" + o.units + "' are unknown; use in (the device's default) or cm");
    output.centimetres = o.units == "cm";
    format = tracking::TrackerFormat::of(tracking::parse_device(o.device), o.binary, output);
    tracking::validate_tracker_format(format);
  } catch (const InputError& e) {
    throw InputError(std::string("tracker decode: ") + e.what());
  }
  if (o.out != "-") refuse_output_over_input(o.out, {o.file});
  const std::string data = read_input_file(o.file, "raw tracker capture");

  std::vector<tracking::ByteChunk> chunks;
  std::size_t ignored_bytes = 0, torn_chunk_bytes = 0;
  if (has_chunk_magic(data)) {
    chunks = capture::parse_tracker_chunks(data, &ignored_bytes, &torn_chunk_bytes);
  } else {
    chunks.push_back({0, std::vector<std::uint8_t>(data.begin(), data.end())});
  }

  tracking::DecodeCounts counts;
  if (o.out.empty() || o.out == "-") {
    counts = tracking::decode_to_csv(chunks, format, std::cout);
    std::cout.flush();
  } else {
    std::ostringstream csv;
    counts = tracking::decode_to_csv(chunks, format, csv);
    write_file_atomically(o.out, csv.str());
  }
  std::string summary = o.file + ": " + tracking::decode_summary(counts);
  if (ignored_bytes > torn_chunk_bytes)
    summary += ", " + std::to_string(ignored_bytes - torn_chunk_bytes) + " bytes of damaged chunks skipped";
  if (torn_chunk_bytes > 0) summary += ", " + std::to_string(torn_chunk_bytes) + " bytes of a torn chunk ignored";
  std::fprintf(stderr, "%s\n", summary.c_str());
}

}  // namespace

void register_tracker_decode(CLI::App& tracker) {
  auto o = std::make_shared<DecodeOptions>();
  auto* cmd =
      tracker.add_subcommand("decode", "Decode raw tracker bytes (or a recording's tracker.raw) into CSV poses");
  cmd->add_option("FILE", o->file, "Raw byte capture, or tracker.raw from a recording")->required();
  // Values are checked when the command runs, so a bad one gets the usual one-line error.
  cmd->add_option("--device", o->device, "Tracker model: isotrak2 or fastrak")->capture_default_str();
  cmd->add_flag("--binary", o->binary, "Records are binary (`f` mode) instead of ASCII");
  cmd->add_option("--units", o->units, "Position units the device sent: in or cm")->capture_default_str();
  cmd->add_option("--list", o->list, "Output list the device was set to (`O` command), e.g. 2,4,1 or 2,11,1")
      ->capture_default_str();
  cmd->add_option("--out", o->out, "CSV file to write (default: standard output)");
  add_action(cmd, [o] { run_decode(*o); });
}

}  // namespace lumar::app
