#include "lumar/pipeline/envmap_images.h"

#include <spdlog/spdlog.h>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "lumar/base/csv.h"
#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/base/output_file.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/camera_response.h"
#include "lumar/capture/image_sequence_source.h"
#include "lumar/pipeline/progress.h"

namespace lumar::pipeline {

namespace fs = std::filesystem;

namespace {

struct PoseRow {
  std::string file;
  glm::dquat rotation{1, 0, 0, 0};
  std::optional<glm::dvec3> position;
  double exposure = 1.0;
  std::optional<int> station;
  int line = 0;
};

std::vector<PoseRow> read_poses_csv(const std::string& path) {
  std::vector<PoseRow> rows;
  std::map<std::string, std::size_t> seen;
  bool positions = false;
  csv::for_each_row(path, read_input_file(path, "image poses file"),
                    {{"file", "qw", "qx", "qy", "qz"}, {"x", "y", "z", "exposure", "station"}, false},
                    csv::LastLine::kRead, [&](const csv::Row& row) {
                      const int xyz = int(row.has("x")) + int(row.has("y")) + int(row.has("z"));
                      if (xyz != 0 && xyz != 3) row.fail("give all of the columns x,y,z or none");
                      positions = xyz == 3;
                      PoseRow r;
                      r.line = int(row.line());
                      r.file = std::string(row.text("file"));
                      if (r.file.empty()) row.fail("the file name is empty");
                      if (auto [it, fresh] = seen.emplace(r.file, row.line()); !fresh)
                        row.fail(r.file + " already has a pose on line " + std::to_string(it->second));
                      const glm::dquat q(row.real("qw"), row.real("qx"), row.real("qy"), row.real("qz"));
                      const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
                      if (std::abs(norm - 1.0) > 1e-3)
                        row.fail("the quaternion of " + r.file + " has length " + std::to_string(norm) +
                                 "; give R_world_camera as a unit quaternion qw,qx,qy,qz");
                      r.rotation = q / norm;
                      if (positions) r.position = glm::dvec3(row.real("x"), row.real("y"), row.real("z"));
                      if (row.has("exposure")) {
                        r.exposure = row.real("exposure");
                        if (!(r.exposure > 0))
                          row.fail("exposure must be positive (video linear value per unit radiance)");
                      }
                      if (row.has("station")) r.station = row.small_integer("station");
                      rows.push_back(r);
                    });
  if (rows.empty()) throw InputError(path + ": no poses; one row per image is needed");
  return rows;
}

std::string key_of(const fs::path& p) { return p.lexically_normal().string(); }

}  // namespace

SweepInput images_sweep_input(const ImagesInputOptions& o, int width) {
  if (o.poses.empty()) throw InputError("--images needs --poses POSES.csv (file,qw,qx,qy,qz per image)");
  if (o.camera.empty())
    throw InputError("--images needs --camera CAM.yml, the calibration of the camera that took them");
  const std::vector<PoseRow> rows = read_poses_csv(o.poses);
  const CameraIntrinsics camera = calib::load_camera_file(o.camera).intrinsics;

  capture::ImageSequenceSettings seq;
  seq.pattern = o.images;
  seq.fps = 1;  // times do not matter here
  auto listing = std::make_shared<capture::ImageSequenceSource>(seq);
  const auto& files = listing->files();
  const cv::Size size = listing->frame_size();
  if (camera.width != size.width || camera.height != size.height)
    throw InputError(o.camera + ": the calibration is for " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + " but " + files.front().string() + " is " +
                     std::to_string(size.width) + "x" + std::to_string(size.height) +
                     "; use the calibration of the camera that took the images");

  // Match rows to images by path relative to the images' folder.
  std::error_code ec;
  const fs::path folder = fs::is_directory(o.images, ec) ? fs::path(o.images) : fs::path(o.images).parent_path();
  std::map<std::string, int> image_index;
  for (int i = 0; i < int(files.size()); ++i) image_index[key_of(files[i])] = i;
  std::vector<int> row_of(files.size(), -1);
  for (int r = 0; r < int(rows.size()); ++r) {
    const fs::path p = folder / rows[r].file;
    const std::string where = o.poses + ":" + std::to_string(rows[r].line) + ": ";
    const auto it = image_index.find(key_of(p));
    if (it == image_index.end()) {
      if (!fs::exists(p, ec))
        throw InputError(where + "the image " + p.string() + " does not exist; add it or drop the row");
      throw InputError(where + p.string() + " is not one of the images of " + o.images +
                       "; drop the row or widen the glob");
    }
    row_of[it->second] = r;
  }
  for (int i = 0; i < int(files.size()); ++i)
    if (row_of[i] < 0)
      throw InputError(o.poses + ": no pose for " + files[i].string() + "; add a row for it or move it out of " +
                       o.images);

  SweepInput in;
  in.name = o.images;
  in.stitch.width = width;
  in.stitch.camera = camera;
  in.stitch.response = o.response.empty() ? calib::srgb_response(1.0) : calib::load_camera_response(o.response);
  in.stitch.vignetting_a = o.vignetting_a;
  in.stitch.vignetting_b = o.vignetting_b;
  in.tracker_noise_deg = o.tracker_noise_deg;
  in.label_header = "file";
  glm::dvec3 position_sum(0.0);
  int positions = 0;
  bool stations = false;
  for (int i = 0; i < int(files.size()); ++i) {
    const PoseRow& r = rows[row_of[i]];
    in.rotations.push_back(r.rotation);
    in.exposures.push_back(r.exposure);
    in.labels.push_back(r.file);
    in.groups.push_back(r.station.value_or(-1 - i));  // no station: a group of its own
    stations = stations || r.station.has_value();
    if (r.position) position_sum += *r.position, ++positions;
  }
  if (!stations) in.groups.clear();
  if (positions > 0) in.stitch.capture_position = position_sum / double(positions);
  const std::string pattern = o.images;
  const int n = int(files.size());
  in.read_frames = [pattern, n](const std::function<void(const cv::Mat&, int)>& use) {
    capture::ImageSequenceSettings s;
    s.pattern = pattern;
    s.fps = 1;
    capture::ImageSequenceSource source(s);  // InputError naming an image that does not decode or changes size
    capture::Frame frame;
    for (int k = 0; k < n && source.read(frame); ++k) use(frame.image, k);
  };
  return in;
}

void export_sweep_images(const SweepInput& in, const std::string& dir_text) {
  const fs::path dir = dir_text;
  OutputFolder folder(dir);  // InputError when it exists: --export-images makes a new folder
  const fs::path& tmp = folder.temporary();
  std::ostringstream csv;
  csv.precision(12);
  csv << "file,qw,qx,qy,qz,x,y,z,exposure" << (in.groups.empty() ? "" : ",station") << '\n';
  const glm::dvec3 p = in.stitch.capture_position;
  Progress progress("exporting", int(in.rotations.size()));
  int done = 0;
  in.read_frames([&](const cv::Mat& image, int k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame-%06d.png", k);
    if (!cv::imwrite((tmp / name).string(), image)) throw RuntimeError((dir / name).string() + ": cannot write");
    const glm::dquat& q = in.rotations[k];
    csv << name << ',' << q.w << ',' << q.x << ',' << q.y << ',' << q.z << ',' << p.x << ',' << p.y << ',' << p.z << ','
        << in.exposures[k];
    if (!in.groups.empty()) csv << ',' << in.groups[k];
    csv << '\n';
    progress.update(++done);
  });
  if (done != int(in.rotations.size())) throw InputError(in.name + ": not every frame could be read");
  write_file_atomically(tmp / "poses.csv", csv.str());
  calib::CameraFile camera;
  camera.intrinsics = in.stitch.camera;
  calib::save_camera_file(tmp / "camera.yml", camera);
  folder.commit();
  spdlog::info(
      "envmap: stitch them with: lumar envmap --images {0} --poses {0}/poses.csv --camera {0}/camera.yml "
      "--vignetting {1} --vignetting-b {2} --out OUT.exr (and the recording's camera response, if not sRGB)",
      dir_text, in.stitch.vignetting_a, in.stitch.vignetting_b);
}

}  // namespace lumar::pipeline
