// lumar tracker: the parent of the tracker subcommands (decode, emulate, record). Each
// subcommand registers itself on it; running `tracker` runs the subcommand the user chose.
#include "commands.h"

namespace lumar::app {

void register_tracker(CLI::App& app) {
  auto* tracker = app.add_subcommand("tracker", "Polhemus ISOTRAK II / Fastrak tools");
  tracker->require_subcommand(1);
  register_tracker_decode(*tracker);
  register_tracker_emulate(*tracker);
  register_tracker_record(*tracker);
  add_action(tracker, [tracker] { run_selected(*tracker); });
}

}  // namespace lumar::app
