#include "lumar/base/output_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "lumar/base/error.h"

namespace lumar {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const fs::path& path, const std::string& what, int err) {
  throw RuntimeError(path.string() + ": cannot " + what + " (" + std::strerror(err) +
                     "); check free space and permissions");
}

fs::path folder_of(const fs::path& path) { return path.has_parent_path() ? path.parent_path() : fs::path("."); }

// ".NAME.partial-PID-N.EXT" beside `path`: unique, so that two processes writing the
// same output (two runs filling one cache) never write into each other's temporary.
fs::path temporary_name(const fs::path& path, bool keep_extension) {
  static std::atomic<unsigned> counter{0};
  const std::string name = keep_extension ? path.stem().string() : path.filename().string();
  const std::string ext = keep_extension ? path.extension().string() : std::string();
  return path.parent_path() /
         ("." + name + ".partial-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ext);
}

void check_folder(const fs::path& path) {
  std::error_code ec;
  if (path.filename().empty() || fs::is_directory(path, ec))
    throw InputError(path.string() + ": is a folder; give a file name for the output");
  if (!fs::is_directory(folder_of(path), ec))
    throw InputError(path.string() + ": folder " + folder_of(path).string() + " does not exist");
}

void rename_or_fail(const fs::path& from, const fs::path& to) {
  if (::rename(from.c_str(), to.c_str()) != 0) fail(to, "move the finished output into place", errno);
}

}  // namespace

void fsync_path(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(path, "open for fsync", errno);
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) fail(path, "fsync", err);
}

OutputFile::OutputFile(fs::path path) : path_(std::move(path)) {
  check_folder(path_);
  temporary_ = temporary_name(path_, true);
}

OutputFile::~OutputFile() {
  if (committed_) return;
  std::error_code ec;
  fs::remove(temporary_, ec);
}

void OutputFile::commit() {
  if (committed_) return;
  std::error_code ec;
  if (!fs::is_regular_file(temporary_, ec)) throw RuntimeError(path_.string() + ": the writer left no file");
  fsync_path(temporary_);
  rename_or_fail(temporary_, path_);
  committed_ = true;
  fsync_path(folder_of(path_));
}

OutputFolder::OutputFolder(fs::path path) : path_(std::move(path)) {
  std::error_code ec;
  if (fs::exists(path_, ec)) throw InputError(path_.string() + ": already exists; choose a new folder");
  if (!fs::is_directory(folder_of(path_), ec))
    throw InputError(path_.string() + ": folder " + folder_of(path_).string() + " does not exist");
  temporary_ = temporary_name(path_, false);
  if (!fs::create_directory(temporary_, ec) || ec)
    throw RuntimeError(path_.string() + ": cannot create the folder (" + ec.message() + ")");
}

OutputFolder::~OutputFolder() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(temporary_, ec);
}

void OutputFolder::commit() {
  if (committed_) return;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(temporary_, ec))
    if (entry.is_regular_file(ec)) fsync_path(entry.path());
  fsync_path(temporary_);
  rename_or_fail(temporary_, path_);
  committed_ = true;
  fsync_path(folder_of(path_));
}

void write_file_atomically(const fs::path& path, std::string_view contents) {
  OutputFile out(path);
  const int fd = ::open(out.temporary().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail(path, "create", errno);
  while (!contents.empty()) {
    const ssize_t n = ::write(fd, contents.data(), contents.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      fail(path, "write", err);
    }
    contents.remove_prefix(std::size_t(n));
  }
  if (::close(fd) != 0) fail(path, "write", errno);
  out.commit();
}

void refuse_output_over_input(const std::filesystem::path& output, const std::vector<std::filesystem::path>& inputs,
                              const std::string& option) {
  std::error_code ec;
  if (output.empty() || !std::filesystem::exists(output, ec)) return;
  for (const auto& input : inputs) {
    if (std::filesystem::equivalent(output, input, ec))
      throw InputError(option + " " + output.string() + " is an input (" + input.string() +
                       "); write the output to another file");
  }
}

}  // namespace lumar
