#include "commands.h"

#include <map>

namespace lumar::app {

namespace {
std::map<CLI::App*, std::function<void()>>& actions() {
  static std::map<CLI::App*, std::function<void()>> m;
  return m;
}
}  // namespace

void add_action(CLI::App* sub, std::function<void()> run) { actions()[sub] = std::move(run); }

void register_commands(CLI::App& app) {
  register_synth(app);
  register_overlay(app);
  register_regress(app);
  register_calibrate(app);
  register_calibrate_rig(app);
  register_radiometry(app);
  register_tracker(app);
  register_devices(app);
  register_record(app);
  register_envmap(app);
  register_shadows(app);
  register_irradiance(app);
}

void run_selected(CLI::App& app) {
  for (auto* sub : app.get_subcommands())
    if (auto it = actions().find(sub); it != actions().end()) it->second();
}

}  // namespace lumar::app
