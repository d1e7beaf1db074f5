#include "bench_report.h"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/output_file.h"
#include "lumar/calib/image_file.h"

namespace lumar::bench {

void BenchReport::compute_ratios() {
  double base = 0;
  for (const auto& e : entries)
    if (e.name == baseline) base = e.time_ms;
  for (auto& e : entries) e.ratio = base > 0 ? e.time_ms / base : 0.0;
}

void BenchReport::write_json(const std::filesystem::path& file) const {
  nlohmann::json j = {{"name", name}, {"title", title}, {"baseline", baseline}, {"error_label", error_label}};
  if (!x_label.empty()) j["x_label"] = x_label;
  if (!highlight.empty()) j["highlight"] = highlight;
  if (!note.empty()) j["note"] = note;
  for (const auto& e : entries) {
    nlohmann::json row = {{"name", e.name}, {"time_ms", e.time_ms}, {"ratio_to_baseline", e.ratio}};
    if (!std::isnan(e.error)) row["error"] = e.error;
    if (!std::isnan(e.x)) row["x"] = e.x;
    j["entries"].push_back(row);
  }
  write_file_atomically(file, j.dump(2) + "\n");
}

namespace {

const cv::Scalar kInk(40, 40, 40), kGrid(225, 225, 225), kBar(180, 120, 60), kDot(40, 90, 200);

void text(cv::Mat& img, const std::string& s, cv::Point at, double scale = 0.45, cv::Scalar colour = kInk) {
  cv::putText(img, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

std::string short_number(double v) { return fmt::format("{:.3g}", v); }

// Round values between 10^l0 and 10^l1 for a log axis: 1, 2, 5 per decade, or finer
// steps when the axis spans less than that gives three of.
std::vector<double> log_ticks(double l0, double l1) {
  for (const auto& mantissas :
       {std::vector<double>{1, 2, 5}, std::vector<double>{1, 1.5, 2, 3, 4, 5, 6, 7, 8},
        std::vector<double>{1, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.8, 2, 2.2, 2.5, 3, 3.5, 4, 4.5, 5, 6, 7, 8, 9}}) {
    std::vector<double> ticks;
    for (double d = std::floor(l0); d <= std::ceil(l1); d += 1)
      for (const double m : mantissas) {
        const double v = m * std::pow(10, d), l = std::log10(v);
        if (l >= l0 && l <= l1) ticks.push_back(v);
      }
    if (ticks.size() >= 3) return ticks;
  }
  return {std::pow(10, 0.5 * (l0 + l1))};
}

// The plot's grid: a line and a label at each tick, px and py mapping values to pixels.
template <class Px, class Py>
void log_grid(cv::Mat& img, const cv::Rect& plot, const std::vector<double>& x_ticks,
              const std::vector<double>& y_ticks, const Px& px, const Py& py) {
  const int top = plot.y, bottom = plot.y + plot.height, left = plot.x, right = plot.x + plot.width;
  for (const double v : x_ticks) {
    cv::line(img, {px(v), top}, {px(v), bottom}, kGrid);
    text(img, short_number(v), {px(v) - 8, bottom + 20}, 0.4);
  }
  for (const double v : y_ticks) {
    cv::line(img, {left, py(v)}, {right, py(v)}, kGrid);
    text(img, short_number(v), {10, py(v) + 5}, 0.4);
  }
}

}  // namespace

void BenchReport::write_chart(const std::filesystem::path& file) const {
  const bool tradeoff = std::any_of(entries.begin(), entries.end(), [](const auto& e) { return !std::isnan(e.error); });
  const bool xy = std::any_of(entries.begin(), entries.end(), [](const auto& e) { return !std::isnan(e.x); });
  // Bars start right of the longest name (at least 260 pixels in).
  int label_width = 240;
  for (const auto& e : entries)
    label_width = std::max(label_width, cv::getTextSize(e.name, cv::FONT_HERSHEY_SIMPLEX, 0.45, 1, nullptr).width);
  // The error-against-time plot is 600 pixels wide with its legend to the right of it.
  const auto legend_line = [](const BenchEntry& e) {
    return fmt::format("{}   {} ms   {}", e.name, short_number(e.time_ms), short_number(e.error));
  };
  int legend_width = 0;
  for (const auto& e : entries)
    legend_width =
        std::max(legend_width, cv::getTextSize(legend_line(e), cv::FONT_HERSHEY_SIMPLEX, 0.4, 1, nullptr).width);
  const int W = tradeoff && !xy ? 90 + 600 + 48 + legend_width + 20 : 660 + label_width;
  const int H = tradeoff ? 560 : 120 + 34 * int(entries.size());
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  text(img, title, {20, 30}, 0.6);
  if (xy) {
    // Error against x, both on log axes (x at or below 0 is drawn at the left edge);
    // the choice, the baseline and the Pareto front are labelled.
    const int left = 90, right = W - 40, top = 60, bottom = H - 80;
    double x0 = 1e300, x1 = 0, e0 = 1e300, e1 = 0;
    for (const auto& e : entries) {
      if (std::isnan(e.x) || std::isnan(e.error)) continue;
      if (e.x > 0) x0 = std::min(x0, e.x), x1 = std::max(x1, e.x);
      e0 = std::min(e0, std::max(e.error, 1e-6)), e1 = std::max(e1, std::max(e.error, 1e-6));
    }
    if (x1 == 0) x0 = x1 = 1;
    const double lx0 = std::floor(std::log10(x0)) - 1, lx1 = std::ceil(std::log10(x1)) + (x1 == x0 ? 1 : 0);
    const double le0 = std::floor(std::log10(e0)), le1 = std::ceil(std::log10(e1)) + (e1 == e0 ? 1 : 0);
    auto px = [&](double x) {
      return left + int((right - left) * (std::log10(std::max(x, std::pow(10, lx0))) - lx0) / (lx1 - lx0));
    };
    auto py = [&](double e) {
      return bottom - int((bottom - top) * (std::log10(std::max(e, 1e-6)) - le0) / (le1 - le0));
    };
    log_grid(img, {left, top, right - left, bottom - top}, log_ticks(lx0, lx1), log_ticks(le0, le1), px, py);
    cv::rectangle(img, {left, top}, {right, bottom}, kInk);
    text(img, x_label + " (log)", {(left + right) / 2 - 120, H - 45});
    text(img, error_label + " (log)", {left, top - 10}, 0.42);
    if (!note.empty()) text(img, note, {20, H - 15}, 0.4);
    for (const auto& e : entries) {
      if (std::isnan(e.x) || std::isnan(e.error)) continue;
      const cv::Point p(px(e.x), py(e.error));
      const bool chosen = e.name == highlight;
      const bool front = std::none_of(entries.begin(), entries.end(), [&](const auto& o) {
        return &o != &e && o.x <= e.x && o.error <= e.error && (o.x < e.x || o.error < e.error);
      });
      cv::circle(img, p, chosen ? 7 : 4,
                 e.name == baseline ? kBar
                 : chosen           ? cv::Scalar(40, 160, 40)
                                    : kDot,
                 cv::FILLED, cv::LINE_AA);
      if (chosen || front || e.name == baseline)
        text(img, e.name, p + cv::Point(9, 4), chosen ? 0.45 : 0.36, chosen ? cv::Scalar(40, 130, 40) : kInk);
    }
  } else if (!tradeoff) {
    // Horizontal bars: one per entry, time in ms, ratio to the baseline after it.
    const int left = label_width + 20 + 16, right = W - 170, top = 60;
    double tmax = 0;
    for (const auto& e : entries) tmax = std::max(tmax, e.time_ms);
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const auto& e = entries[i];
      const int y = top + 34 * int(i);
      const int len = tmax > 0 ? int((right - left) * e.time_ms / tmax) : 0;
      text(img, e.name, {20, y + 18});
      cv::rectangle(img, {left, y + 4}, {left + std::max(1, len), y + 24}, e.name == baseline ? kDot : kBar,
                    cv::FILLED);
      text(img, fmt::format("{} ms  x{:.2f}", short_number(e.time_ms), e.ratio), {left + len + 8, y + 19});
    }
    text(img, fmt::format("ratios against '{}' measured in the same run", baseline), {20, H - 20}, 0.42);
  } else {
    // Error against time, both on log axes. Points are numbered (each number placed where
    // it overlaps no other) and a legend beside the plot names them with their values,
    // since configurations of similar cost and error cluster and their names would not fit.
    const int left = 90, right = left + 600, top = 60, bottom = H - 70;
    double t0 = 1e300, t1 = 0, e0 = 1e300, e1 = 0;
    for (const auto& e : entries) {
      if (std::isnan(e.error)) continue;
      t0 = std::min(t0, e.time_ms), t1 = std::max(t1, e.time_ms);
      e0 = std::min(e0, std::max(e.error, 1e-6)), e1 = std::max(e1, std::max(e.error, 1e-6));
    }
    // Log axes around the points, not whole decades: configurations of one method often
    // lie within a few tens of percent of each other and would huddle in one corner.
    const double lt0 = std::log10(t0) - 0.08, lt1 = std::log10(t1) + 0.08;
    const double le0 = std::log10(e0) - 0.1, le1 = std::log10(e1) + 0.1;
    auto px = [&](double t) { return left + int((right - left) * (std::log10(t) - lt0) / (lt1 - lt0)); };
    auto py = [&](double e) {
      return bottom - int((bottom - top) * (std::log10(std::max(e, 1e-6)) - le0) / (le1 - le0));
    };
    log_grid(img, {left, top, right - left, bottom - top}, log_ticks(lt0, lt1), log_ticks(le0, le1), px, py);
    cv::rectangle(img, {left, top}, {right, bottom}, kInk);
    text(img, "time per operation (ms, log)", {(left + right) / 2 - 100, H - 25});
    text(img, error_label + " (log)", {left, top - 10}, 0.42);
    // Dots first, so that numbers avoid every dot, not only the ones drawn before them.
    std::vector<cv::Rect> taken;
    const auto colour_of = [&](const BenchEntry& e) {
      return e.name == highlight ? cv::Scalar(40, 160, 40) : e.name == baseline ? kBar : kDot;
    };
    for (const auto& e : entries) {
      if (std::isnan(e.error)) continue;
      const cv::Point p(px(e.time_ms), py(e.error));
      const int r = e.name == highlight ? 7 : 5;
      cv::circle(img, p, r, colour_of(e), cv::FILLED, cv::LINE_AA);
      taken.push_back(cv::Rect(p.x - r, p.y - r, 2 * r + 1, 2 * r + 1));
    }
    const double legend_row = std::min(20.0, double(bottom - top) / std::max<std::size_t>(1, entries.size()));
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const auto& e = entries[i];
      const std::string number = std::to_string(i + 1);
      const int y = top + 12 + int(legend_row * double(i));
      text(img, number, {right + 20, y}, 0.4, colour_of(e));
      text(img, legend_line(e), {right + 48, y}, 0.4);
      if (std::isnan(e.error)) continue;
      const cv::Point p(px(e.time_ms), py(e.error));
      const cv::Size size = cv::getTextSize(number, cv::FONT_HERSHEY_SIMPLEX, 0.4, 1, nullptr);
      // Candidate places around the dot (text origin is its lower left corner); the first
      // free one, else the least covered.
      const cv::Point offsets[] = {{8, -4},
                                   {8, 12},
                                   {-8 - size.width, -4},
                                   {-8 - size.width, 12},
                                   {-size.width / 2, -9},
                                   {-size.width / 2, 9 + size.height},
                                   {14, -14},
                                   {14, 22},
                                   {-14 - size.width, -14},
                                   {-14 - size.width, 22}};
      cv::Rect best;
      int best_overlap = INT32_MAX;
      for (const cv::Point& o : offsets) {
        const cv::Rect box(p.x + o.x, p.y + o.y - size.height, size.width, size.height);
        int overlap = 0;
        for (const cv::Rect& t : taken) overlap += (box & t).area();
        if (overlap < best_overlap) best_overlap = overlap, best = box;
        if (overlap == 0) break;
      }
      taken.push_back(best);
      text(img, number, {best.x, best.y + best.height}, 0.4, colour_of(e));
    }
    if (!note.empty()) text(img, note, {20, H - 5}, 0.4);
  }
  calib::write_image_atomically(file, img);
}

void BenchReport::publish(std::size_t expected_entries) const {
  if (entries.size() != expected_entries) {
    std::printf("a filtered run: the chart and JSON are left as they are\n");
    return;
  }
  save(results_dir());
  std::filesystem::copy_file(results_dir() / (name + ".png"),
                             std::filesystem::path(LUMAR_SOURCE_DIR) / "docs" / (name + ".png"),
                             std::filesystem::copy_options::overwrite_existing);
}

cv::Mat crops_side_by_side(const std::vector<cv::Mat>& images, const cv::Rect& crop, double scale) {
  std::vector<cv::Mat> parts;
  for (const cv::Mat& image : images) {
    cv::Mat big;
    cv::resize(image(crop), big, {}, scale, scale, cv::INTER_NEAREST);
    parts.push_back(big);
  }
  cv::Mat picture;
  cv::hconcat(parts, picture);
  return picture;
}

void publish_stacked(const std::vector<BenchReport>& reports, const std::string& docs_png) {
  std::vector<cv::Mat> charts;
  int width = 0;
  for (const auto& r : reports) {
    r.save(results_dir());
    charts.push_back(cv::imread((results_dir() / (r.name + ".png")).string(), cv::IMREAD_COLOR));
    width = std::max(width, charts.back().cols);
  }
  for (cv::Mat& c : charts)
    cv::copyMakeBorder(c, c, 0, 0, 0, width - c.cols, cv::BORDER_CONSTANT, cv::Scalar(255, 255, 255));
  cv::Mat stacked;
  cv::vconcat(charts, stacked);
  calib::write_image_atomically(std::filesystem::path(LUMAR_SOURCE_DIR) / "docs" / docs_png, stacked);
}

void BenchReport::save(const std::filesystem::path& dir) const {
  std::filesystem::create_directories(dir);
  write_json(dir / (name + ".json"));
  write_chart(dir / (name + ".png"));
  std::printf("\n%s\n%-34s %12s %10s %14s %10s\n", title.c_str(), "entry", "ms/op", "x baseline",
              error_label.empty() ? "" : "error", x_label.empty() ? "" : "x");
  for (const auto& e : entries)
    std::printf("%-34s %12.4g %10.3f %14s %10s\n", e.name.c_str(), e.time_ms, e.ratio,
                std::isnan(e.error) ? "" : fmt::format("{:.4g}", e.error).c_str(),
                std::isnan(e.x) ? "" : fmt::format("{:.4g}", e.x).c_str());
  std::printf("-> %s/%s.{json,png}\n", dir.c_str(), name.c_str());
}

std::filesystem::path results_dir() {
  if (const char* env = std::getenv("LUMAR_BENCH_OUT"); env && *env) return env;
  return std::filesystem::path(LUMAR_SOURCE_DIR) / "bench" / "results";
}

}  // namespace lumar::bench

namespace lumar::bench {

const CollectingReporter::Result* CollectingReporter::find(const std::string& name) const {
  for (const auto& [key, result] : results_)
    if (key == name || key.rfind(name + "/", 0) == 0) return &result;
  return nullptr;
}

void CollectingReporter::ReportRuns(const std::vector<Run>& runs) {
  benchmark::ConsoleReporter::ReportRuns(runs);
  for (const Run& run : runs) {
    if (run.run_type != Run::RT_Iteration || run.error_occurred) continue;
    Result r;
    const double to_ms = 1e3 / benchmark::GetTimeUnitMultiplier(run.time_unit);
    r.time_ms = run.GetAdjustedRealTime() * to_ms;
    for (const auto& [k, c] : run.counters) r.counters[k] = c.value;
    results_[run.benchmark_name()] = r;
  }
}

void register_measured_once(const std::string& name, const std::function<double(benchmark::State&)>& measure) {
  benchmark::RegisterBenchmark(name.c_str(),
                               [measure](benchmark::State& state) {
                                 for (auto _ : state) state.SetIterationTime(measure(state) * 1e-3);
                               })
      ->UseManualTime()
      ->Iterations(1)
      ->Unit(benchmark::kMillisecond);
}

void run_benchmarks(int& argc, char** argv, CollectingReporter& reporter) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks(&reporter);
}

}  // namespace lumar::bench
