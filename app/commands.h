#pragma once
// Subcommands of `lumar`. Each cmd_*.cpp defines one register_* function that adds its
// subcommand and the action to run when the user chose it.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "lumar/pipeline/live_inputs.h"
#include "lumar/pipeline/overlay.h"
#include "lumar/pipeline/quality_choice.h"

namespace lumar::app {

void register_commands(CLI::App& app);
// Runs the subcommand the user chose (after parsing).
void run_selected(CLI::App& app);
// Used by the register_* functions.
void add_action(CLI::App* subcommand, std::function<void()> run);
// The live inputs' options (all but --source), with the same names in every command.
void add_live_input_options(
    CLI::App* cmd, pipeline::LiveInputOptions& o,
    const std::string& camera_help = "Camera calibration (OpenCV YAML); default: a nominal pinhole");

// --without and --blur-sigma: what makes rendered pixels look like the camera's
// (gl::CompositeFeatures); --shading: the objects' light per pixel or per vertex
// (ObjectShading); --shadow-lines: lines per receiver and emitter patch, --contact-moving:
// the contact receivers at every pose of a moving object (ShadowQuality);
// --exact-lights and --shadow-map: the volume's lights evaluated with shadow maps, and
// their maps' size (pipeline::OverlayQuality); --quality auto and --quality-budget: those
// knobs chosen on a recording's frames (pipeline/quality_choice.h).
// The same names in every command that composites.
struct CompositeOptions {
  std::string without;
  double blur_sigma_px = -1.0;
  double shutter_s = -1.0;  // -1: the session's
  int shutter_instants = pipeline::OverlaySettings{}.shutter_instants;
  std::string shading = "pixel";
  int shadow_lines = ShadowQuality{}.lines_per_patch;
  bool contact_moving = ShadowQuality{}.contact_while_moving;
  int exact_lights = -1;  // -1: the manifest's
  int shadow_map = -1;    // -1: the manifest's
  double coverage_mesh_px = pipeline::OverlayQuality{}.coverage_mesh_px;
  std::string quality = "full";
  double quality_budget = pipeline::QualityBudget{}.percent;
  int quality_frames = pipeline::QualityBudget{}.frames;
};
void add_composite_options(CLI::App* cmd, CompositeOptions& o);
// Applies them to `settings`; InputError names an unknown feature.
void apply_composite_options(const CompositeOptions& o, pipeline::OverlaySettings& settings);
// --quality auto: the budget for the choice (ReplayOverlaySettings::auto_quality, live
// LiveOverlayOptions::auto_quality);
// nullopt for full. InputError for another word or a budget out of range.
std::optional<pipeline::QualityBudget> auto_quality(const CompositeOptions& o);

void register_synth(CLI::App& app);
// `lumar solidify`: a closed solid around an open scan.
void register_solidify(CLI::App& app);
void register_overlay(CLI::App& app);
void register_regress(CLI::App& app);
void register_calibrate(CLI::App& app);
// `lumar calibrate-rig`: tracker-to-camera offset and latency from a board recording.
void register_calibrate_rig(CLI::App& app);
// `lumar calibrate-response` and `lumar calibrate-vignetting`.
void register_radiometry(CLI::App& app);
// `lumar tracker ...`: the parent command; its subcommands register themselves on it.
void register_tracker(CLI::App& app);
void register_tracker_decode(CLI::App& tracker);
void register_tracker_emulate(CLI::App& tracker);
void register_tracker_record(CLI::App& tracker);
// `lumar devices`: serial ports, Polhemus USB devices and USB-serial adapters.
void register_devices(CLI::App& app);
// `lumar record`: frames from any source plus a tracker into a recording.
void register_record(CLI::App& app);
// `lumar envmap`: stitch an HDR environment map from a tracked sweep.
void register_envmap(CLI::App& app);
// `lumar shadows`: shadow attenuation of query points by the scene's objects.
void register_shadows(CLI::App& app);
// `lumar irradiance`: irradiance at query points (volume, SH9, reference, ...).
void register_irradiance(CLI::App& app);

}  // namespace lumar::app
