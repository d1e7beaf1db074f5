#pragma once
#include <CLI/CLI.hpp>
#include <functional>

namespace lumar::app {

// Adds every subcommand to `app`.
void register_commands(CLI::App& app);
// Runs the subcommand the user chose (after parsing).
void run_selected(CLI::App& app);

}  // namespace lumar::app
