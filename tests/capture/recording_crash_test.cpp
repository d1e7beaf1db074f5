// kill -9 in the middle of recording leaves a directory that reads cleanly: only
// closed segments are listed, every listed frame decodes, the logs hold an intact
// prefix of what was written.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "lumar/capture/recording_reader.h"
#include "lumar/capture/recording_writer.h"
#include "recording_test_support.h"
#include "test_paths.h"

namespace lumar::capture {
namespace {
namespace fs = std::filesystem;

constexpr const char* kChildEnv = "LUMAR_TEST_RECORDING_WRITER_DIR";
const cv::Size kSize(320, 240);

[[noreturn]] void run_writer_child(const char* dir) {
  try {
    RecordingSettings settings;
    settings.size = kSize;
    RecordingWriter writer(dir, {{"role", "kill -9 child"}}, settings);
    for (int i = 0; i < 20000; ++i) {
      writer.add_frame({test::numbered_image(i, kSize), i * test::kFramePeriod, i});
      writer.add_tracker_bytes(test::numbered_chunk(i));
      writer.add_pose(test::numbered_sample(i));
      usleep(1000);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "writer child: %s\n", e.what());
    _exit(4);
  }
  _exit(3);  // the parent should have killed this process long before
}

// The test re-executes this binary (a forked copy of a process with OpenCV's thread
// pool is not safe to encode video in); that copy becomes the writer here, before
// main(), and never runs a test.
[[maybe_unused]] const bool kIsWriterChild = [] {
  if (const char* dir = std::getenv(kChildEnv)) run_writer_child(dir);
  return false;
}();

std::size_t count_lines(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::size_t n = 0;
  for (char c; in.get(c);) n += c == '\n';
  return n;
}

bool has_partial_segment(const fs::path& video_dir) {
  std::error_code ec;
  for (fs::directory_iterator it(video_dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().filename().string().find(".partial") != std::string::npos) return true;
  return false;
}

// Kills and reaps the child if a test assertion leaves early.
struct ChildGuard {
  pid_t pid;
  bool reaped = false;
  ~ChildGuard() {
    if (reaped) return;
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }
};

TEST(RecordingCrash, KillNineLeavesAReadableRecording) {
  const fs::path dir = test::scratch_dir("kill-nine") / "rec";
  const test::RemoveOnSuccess cleanup{dir.parent_path()};

  // Everything the child needs is prepared before fork(): after it, only
  // async-signal-safe calls.
  std::string exe = fs::read_symlink("/proc/self/exe").string();
  std::string child_env = std::string(kChildEnv) + "=" + dir.string();
  std::vector<char*> envp;
  for (char** e = environ; *e; ++e) envp.push_back(*e);
  envp.push_back(child_env.data());
  envp.push_back(nullptr);
  char* argv[] = {exe.data(), nullptr};
  const pid_t parent = getpid();

  const pid_t pid = fork();
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive a crashed test
    if (getppid() != parent) _exit(5);
    execve(exe.c_str(), argv, envp.data());
    _exit(127);
  }
  ASSERT_GT(pid, 0);
  ChildGuard guard{pid};

  // Kill once two segments are listed, a third is half written, and tracker bytes
  // and poses have reached their files. The deadline only guards against a hang.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  bool ready = false;
  while (!ready && std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      guard.reaped = true;
      FAIL() << "the writer child exited early with status " << status;
    }
    std::error_code ec;
    ready = count_lines(dir / "frames.csv") >= 61 && has_partial_segment(dir / "video") &&
            fs::file_size(dir / "tracker.raw", ec) > 0 && !ec && count_lines(dir / "poses.csv") >= 2;
    if (!ready) usleep(2000);
  }
  ASSERT_TRUE(ready) << "the writer child made no progress";
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  guard.reaped = true;
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;

  const RecordingReader reader(dir);
  EXPECT_FALSE(reader.complete());
  const nlohmann::json session = test::session_file(dir);
  EXPECT_EQ(session["complete"], false);
  EXPECT_FALSE(session.contains("frames"));
  EXPECT_EQ(session["role"], "kill -9 child");

  const auto& frames = reader.frames();
  EXPECT_GE(frames.size(), 60u);
  EXPECT_EQ(frames.size() % 30, 0u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].index, std::int64_t(i));
    EXPECT_EQ(frames[i].time, std::int64_t(i) * test::kFramePeriod);
  }
  for (int s = 0; s < int(frames.size() / 30); ++s) {
    const fs::path segment = reader.segment_file(s);
    EXPECT_TRUE(fs::exists(segment)) << segment;
    EXPECT_EQ(segment.string().find(".partial"), std::string::npos) << segment;
  }

  auto source = reader.open_frames();
  Frame frame;
  std::size_t decoded = 0;
  while (source->read(frame)) {
    EXPECT_LT(test::mean_abs_diff(frame.image, test::numbered_image(frame.index, kSize)), 2.0)
        << "frame " << frame.index;
    ++decoded;
  }
  EXPECT_EQ(decoded, frames.size());

  // The logs hold an intact prefix of what the child wrote, CRCs checked.
  const auto chunks = reader.tracker_chunks();
  ASSERT_FALSE(chunks.empty());
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    EXPECT_EQ(chunks[i].arrival, test::numbered_chunk(int(i)).arrival);
    EXPECT_EQ(chunks[i].bytes, test::numbered_chunk(int(i)).bytes);
  }
  const auto poses = reader.poses();
  ASSERT_FALSE(poses.empty());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(poses[i].time, test::numbered_sample(int(i)).time);
    test::expect_same_pose(poses[i].T_transmitter_sensor, test::numbered_pose(int(i)));
  }
  RecordProperty("listed_frames", int(frames.size()));
  RecordProperty("tracker_chunks", int(chunks.size()));
}

}  // namespace
}  // namespace lumar::capture
