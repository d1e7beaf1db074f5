#pragma once
// The common way benchmarks record results: entries with a time, optionally an error
// against a reference, and a ratio to a baseline measured in the same run; written as
// JSON and drawn as a PNG chart (bars of time, or time against error).
#include <filesystem>
#include <limits>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace lumar::bench {

struct BenchEntry {
  std::string name;
  double time_ms = 0;                                       // per operation
  double error = std::numeric_limits<double>::quiet_NaN();  // against the reference; NaN = not measured
  double ratio = 0;                                         // time_ms / baseline time_ms
  // A second measured quantity for an x/y chart (e.g. lag in ms); NaN = not measured.
  double x = std::numeric_limits<double>::quiet_NaN();
};

struct BenchReport {
  std::string name;  // file stem: bench/results/<name>.json and .png
  std::string title;
  std::string baseline;     // entry whose time every ratio divides by
  std::string error_label;  // what `error` measures, e.g. "mean relative irradiance error (%)"
  // x/y chart: when entries carry `x`, the chart is `error` against `x` (log axes; x <= 0
  // sits at the left edge) labelled x_label; `highlight` names an entry drawn larger,
  // e.g. a choice; the Pareto front (no entry both lower and left) is labelled.
  std::string x_label;
  std::string highlight;
  std::string note;  // one line printed under the chart
  std::vector<BenchEntry> entries;

  void compute_ratios();
  void write_json(const std::filesystem::path& file) const;
  // Bars of time per entry (ratio printed beside), or, when entries carry errors, a
  // scatter of error against time on log axes: the speed/accuracy chart; or, when they
  // carry x, error against x (see x_label).
  void write_chart(const std::filesystem::path& file) const;
  // Writes <dir>/<name>.json and <dir>/<name>.png and prints a table.
  void save(const std::filesystem::path& dir) const;
  // A chart the docs show: when the run measured `expected_entries` (not a filtered run),
  // saves into results_dir() and copies the PNG to docs/<name>.png in the source tree;
  // otherwise leaves both as they are and says so.
  void publish(std::size_t expected_entries) const;
};

// Charts of the same runs (e.g. one per image region) that the docs show together: saves
// each into results_dir() and writes them one above the other to docs/<docs_png>.
void publish_stacked(const std::vector<BenchReport>& reports, const std::string& docs_png);

// The same part `crop` of each image, enlarged `scale` times (nearest pixel, so pixels
// stay pixels), side by side: the before / after / truth pictures the docs show.
cv::Mat crops_side_by_side(const std::vector<cv::Mat>& images, const cv::Rect& crop, double scale);

// Where results go: $LUMAR_BENCH_OUT, else bench/results in the source tree.
std::filesystem::path results_dir();

}  // namespace lumar::bench

#include <benchmark/benchmark.h>

#include <functional>
#include <map>

namespace lumar::bench {

// Console output as usual, and every run's time (ms per iteration) and counters kept
// for the report.
class CollectingReporter : public benchmark::ConsoleReporter {
 public:
  struct Result {
    double time_ms = 0;
    std::map<std::string, double> counters;
  };
  void ReportRuns(const std::vector<Run>& runs) override;
  const std::map<std::string, Result>& results() const { return results_; }
  // The result of the benchmark registered as `name` (Google Benchmark appends
  // "/min_time:..." and the like to the names it reports); nullptr if it did not run.
  const Result* find(const std::string& name) const;

 private:
  std::map<std::string, Result> results_;
};

// A benchmark that runs its measurement once and reports the time the measurement gives
// (ms per operation) rather than the wall time of the run: for costs measured inside a
// larger replay. `measure` may set counters on the state.
void register_measured_once(const std::string& name, const std::function<double(benchmark::State&)>& measure);

// Runs the registered benchmarks (the command line's --benchmark_filter applies) and keeps
// their results.
void run_benchmarks(int& argc, char** argv, CollectingReporter& reporter);

}  // namespace lumar::bench
