#include "commands.h"

#include <fmt/format.h>

#include <map>
#include <string>

#include "lumar/lighting/irradiance_volume.h"

namespace lumar::app {

namespace {
std::map<CLI::App*, std::function<void()>>& actions() {
  static std::map<CLI::App*, std::function<void()>> m;
  return m;
}
}  // namespace

void add_action(CLI::App* sub, std::function<void()> run) { actions()[sub] = std::move(run); }

void add_composite_options(CLI::App* cmd, CompositeOptions& o) {
  cmd->add_option(
      "--without", o.without,
      "Switch off what makes the objects look like the camera's pixels: a comma-separated list of "
      "antialiasing, self-occlusion, noise, blur, chroma (the codec's chroma subsampling), bounce, lines (the shadows' radiosity lines; without them, "
      "the 2004 system's bounding-sphere shadows), contact (the dense receivers where an object touches the floor), "
      "motion-blur (the objects drawn over the shutter's time), or all (docs/ground_truth.md)");
  cmd->add_option("--blur-sigma", o.blur_sigma_px,
                  "The camera's blur as a Gaussian of this many output pixels (default: estimated from the video)")
      ->check(CLI::Range(0.0, 4.0));
  cmd->add_option("--shutter", o.shutter_s,
                  "How long the camera's shutter was open per frame, seconds, for the objects' motion blur "
                  "(default: live, the camera's exposure time where it says it, else the session's radiometry.shutter_s; "
                  "0: no motion blur)");
  cmd->add_option("--shutter-instants", o.shutter_instants,
                  "Motion blur: the instants of the shutter the objects are drawn at and averaged over (each costs "
                  "one more drawing of them)")
      ->capture_default_str();
  cmd->add_option("--shading", o.shading,
                  "Where the objects' light from the irradiance volume is evaluated: pixel (every covered pixel) or "
                  "vertex (their vertices, again only when they move; docs/irradiance.md)")
      ->capture_default_str();
  cmd->add_option("--shadow-lines", o.shadow_lines,
                  "Shadow lines per receiver and emitter patch: fewer trace a moving object's shadow faster and "
                  "coarser (docs/shadows.md)")
      ->capture_default_str();
  cmd->add_flag("--contact-moving", o.contact_moving,
               "Build the contact shadows at the feet at every pose of a moving object too, not only once the "
               "objects stand still: a build per frame that moved (about 0.8 s for the walk's two figurines), for "
               "offline renders (docs/shadows.md)");
  cmd->add_option("--exact-lights", o.exact_lights,
                  "The irradiance volume's exact lights, evaluated with shadow maps (0 to 16; default: the manifest's "
                  "lighting.irradiance.max_lights, else 16; docs/irradiance.md)");
  cmd->add_option("--quality", o.quality,
                  "full: the knobs as given; auto: before the run, the cheapest knobs whose composite stays within "
                  "--quality-budget of theirs, measured on a few of the recording's frames (live: on the camera's "
                  "first frames; docs/results.md)")
      ->capture_default_str();
  cmd->add_option("--quality-frames", o.quality_frames,
                  "--quality auto: frames each trial composites and times (after one untimed); fewer choose sooner "
                  "from less of the video")
      ->capture_default_str();
  cmd->add_option("--quality-budget", o.quality_budget,
                  "--quality auto: how far each region (object, edge, shadow) may be from full quality, percent")
      ->capture_default_str();
  cmd->add_option("--shadow-map", o.shadow_map,
                  "Texels per side of each exact light's shadow map (8 to 1024; default: the manifest's "
                  "lighting.irradiance.shadow_map_resolution, else 128)");
  cmd->add_option("--coverage-mesh", o.coverage_mesh_px,
                  "Antialiasing: find the objects' coverage of each pixel from their coarsest simplified meshes "
                  "whose surface stays within this many output pixels of the mesh (0: the meshes as given; up to 8; "
                  "docs/results.md)")
      ->capture_default_str();
}

void apply_composite_options(const CompositeOptions& o, pipeline::OverlaySettings& settings) {
  const std::string& without = o.without;
  gl::CompositeFeatures& f = settings.features;
  std::stringstream list(without);
  for (std::string name; std::getline(list, name, ',');) {
    if (name == "antialiasing")
      f.antialiasing = false;
    else if (name == "self-occlusion")
      f.self_occlusion = false;
    else if (name == "noise")
      f.noise = false;
    else if (name == "blur")
      f.blur = false;
    else if (name == "bounce")
      f.bounce = false;
    else if (name == "lines")
      f.lines = false;
    else if (name == "contact")
      f.contact = false;
    else if (name == "chroma")
      f.chroma = false;
    else if (name == "motion-blur")
      f.motion_blur = false;
    else if (name == "all")
      f = gl::CompositeFeatures::none();
    else
      throw InputError(
          "--without " + without + ": unknown feature '" + name +
          "'; use antialiasing, self-occlusion, noise, blur, chroma, bounce, lines, contact, motion-blur or all");
  }
  if (o.blur_sigma_px >= 0) settings.blur_sigma_px = o.blur_sigma_px;
  if (o.shutter_s != -1.0) {
    if (!(o.shutter_s >= 0.0 && o.shutter_s <= 1.0))
      throw InputError(fmt::format("--shutter {}: use 0 (no motion blur) to 1 second", o.shutter_s));
    settings.shutter_s = o.shutter_s;
  }
  if (o.shutter_instants < pipeline::OverlaySettings::kMinShutterInstants ||
      o.shutter_instants > pipeline::OverlaySettings::kMaxShutterInstants)
    throw InputError(fmt::format("--shutter-instants {}: use {} to {}", o.shutter_instants,
                                 pipeline::OverlaySettings::kMinShutterInstants,
                                 pipeline::OverlaySettings::kMaxShutterInstants));
  settings.shutter_instants = o.shutter_instants;
  if (o.shading != "pixel" && o.shading != "vertex")
    throw InputError("--shading " + o.shading + ": use pixel or vertex");
  pipeline::OverlayQuality& q = settings.quality;
  q.shading = o.shading == "vertex" ? ObjectShading::PerVertex : ObjectShading::PerPixel;
  if (o.shadow_lines < 1 || o.shadow_lines > ShadowQuality::kMaxLinesPerPatch)
    throw InputError(fmt::format("--shadow-lines {}: use 1 to {} lines per patch", o.shadow_lines,
                                 ShadowQuality::kMaxLinesPerPatch));
  q.shadows.lines_per_patch = o.shadow_lines;
  q.shadows.contact_while_moving = o.contact_moving;
  if (o.exact_lights != -1) {
    if (o.exact_lights < 0 || o.exact_lights > kMaxExactLights)
      throw InputError(fmt::format("--exact-lights {}: use 0 to {}", o.exact_lights, kMaxExactLights));
    q.exact_lights = o.exact_lights;
  }
  if (o.shadow_map != -1) {
    if (o.shadow_map < kMinShadowMapResolution || o.shadow_map > kMaxShadowMapResolution)
      throw InputError(fmt::format("--shadow-map {}: use {} to {} texels per side", o.shadow_map,
                                   kMinShadowMapResolution, kMaxShadowMapResolution));
    q.shadow_map = o.shadow_map;
  }
  if (!(o.coverage_mesh_px >= 0.0 && o.coverage_mesh_px <= gl::Renderer::kMaxCoverageErrorPx))
    throw InputError(fmt::format("--coverage-mesh {}: use 0 (the meshes as given) to {} pixels", o.coverage_mesh_px,
                                 gl::Renderer::kMaxCoverageErrorPx));
  q.coverage_mesh_px = o.coverage_mesh_px;
}

std::optional<pipeline::QualityBudget> auto_quality(const CompositeOptions& o) {
  if (o.quality != "full" && o.quality != "auto") throw InputError("--quality " + o.quality + ": use full or auto");
  if (!(o.quality_budget > 0.0 && o.quality_budget <= 100.0))
    throw InputError(fmt::format("--quality-budget {}: use a percentage above 0, up to 100", o.quality_budget));
  if (!(o.quality_frames >= 1 && o.quality_frames <= 60))
    throw InputError(fmt::format("--quality-frames {}: use 1 to 60", o.quality_frames));
  if (o.quality == "full") return std::nullopt;
  return pipeline::QualityBudget{.percent = o.quality_budget, .frames = o.quality_frames};
}

void add_live_input_options(CLI::App* cmd, pipeline::LiveInputOptions& o, const std::string& camera_help) {
  cmd->add_option("--timestamps", o.timestamps, "images: a file,time_ns table of the frames");
  cmd->add_option("--images-fps", o.images_fps, "images: fixed frame rate when there is no table");
  cmd->add_option("--video-width", o.width, "v4l2: frame width to ask for")->capture_default_str();
  cmd->add_option("--video-height", o.height, "v4l2: frame height to ask for")->capture_default_str();
  cmd->add_option("--camera-fps", o.camera_fps, "v4l2: frame rate to ask for")->capture_default_str();
  cmd->add_option("--format", o.pixel_format, "v4l2: pixel format (YUYV or MJPG; default: YUYV, then MJPG)");
  cmd->add_option("--v4l2-exposure", o.exposure_100us, "v4l2: exposure in 100 us units (default: leave)");
  cmd->add_option("--gain", o.gain, "v4l2: sensor gain (default: leave)");
  cmd->add_flag("--auto-exposure", o.auto_exposure, "v4l2: leave auto exposure on (radiometry assumes it is locked)");
  cmd->add_option("--tracker", o.tracker, "Tracker on a serial port, e.g. serial:/dev/ttyUSB0 (default: none)");
  cmd->add_option("--tracker-device", o.tracker_model, "Tracker: isotrak2 or fastrak")->capture_default_str();
  cmd->add_option("--baud", o.baud, "Tracker line speed")->capture_default_str();
  cmd->add_option("--latency-ms", o.latency_ms, "Tracker device latency, subtracted from pose times")
      ->capture_default_str();
  cmd->add_option("--camera", o.camera_file, camera_help);
}

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
  register_solidify(app);
}

void run_selected(CLI::App& app) {
  for (auto* sub : app.get_subcommands())
    if (auto it = actions().find(sub); it != actions().end()) it->second();
}

}  // namespace lumar::app
