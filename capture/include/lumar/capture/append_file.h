#pragma once
// Logs that a crash cannot tear: append-only files. What was flushed survives kill -9,
// what was synced also survives a power cut, and a reader only has to ignore a torn
// tail. (Whole files are replaced atomically instead: lumar/base/output_file.h.)
#include <filesystem>
#include <string>
#include <string_view>

namespace lumar::capture {

// An append-only file with its own buffer. append() only queues bytes; flush()
// hands them to the kernel in one go (so the file only ever grows by whole
// appends, barring a full disk); sync() also waits for the disk.
// Not thread-safe: callers lock around it. Only datasync() may run concurrently
// with append()/flush() from another thread.
class AppendFile {
 public:
  AppendFile() = default;
  // Opens for appending, creating the file if needed. RuntimeError naming it on failure.
  explicit AppendFile(const std::filesystem::path& path);
  ~AppendFile();  // flushes what it can; never throws
  AppendFile(AppendFile&& other) noexcept;
  AppendFile& operator=(AppendFile&& other) noexcept;
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;

  bool is_open() const { return fd_ >= 0; }
  const std::filesystem::path& path() const { return path_; }

  void append(std::string_view bytes);  // flushes by itself once 1 MiB is queued
  void flush();                         // write(2) everything queued
  void datasync();                      // fdatasync(2) of what was flushed
  void sync() {
    flush();
    datasync();
  }
  void close();  // sync, then close; RuntimeError on failure

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  std::string pending_;
};

}  // namespace lumar::capture
