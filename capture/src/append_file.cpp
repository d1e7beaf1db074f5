#include "lumar/capture/append_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "lumar/base/error.h"

namespace lumar::capture {
namespace {

constexpr std::size_t kAutoFlushBytes = 1 << 20;

[[noreturn]] void fail(const std::filesystem::path& path, const char* what, int err) {
  throw RuntimeError(path.string() + ": cannot " + what + " (" + std::strerror(err) +
                     "); check free space and permissions");
}

}  // namespace

AppendFile::AppendFile(const std::filesystem::path& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) fail(path, "open for appending", errno);
}

AppendFile::~AppendFile() {
  if (fd_ < 0) return;
  try {
    flush();
  } catch (...) {
    // A destructor cannot report; close() is the place to learn about failures.
  }
  ::close(fd_);
}

AppendFile::AppendFile(AppendFile&& other) noexcept
    : path_(std::move(other.path_)), fd_(std::exchange(other.fd_, -1)), pending_(std::move(other.pending_)) {}

AppendFile& AppendFile::operator=(AppendFile&& other) noexcept {
  if (this != &other) {
    AppendFile old(std::move(*this));
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
    pending_ = std::move(other.pending_);
  }
  return *this;
}

void AppendFile::append(std::string_view bytes) {
  if (fd_ < 0) throw RuntimeError(path_.string() + ": append after close (a bug in the caller)");
  pending_.append(bytes);
  if (pending_.size() >= kAutoFlushBytes) flush();
}

void AppendFile::flush() {
  if (fd_ < 0) return;
  // Drop what reached the kernel even when a later write fails, so a retry never
  // writes bytes twice.
  std::size_t done = 0;
  try {
    while (done < pending_.size()) {
      const ssize_t n = ::write(fd_, pending_.data() + done, pending_.size() - done);
      if (n < 0) {
        if (errno == EINTR) continue;
        fail(path_, "write", errno);
      }
      done += std::size_t(n);
    }
  } catch (...) {
    pending_.erase(0, done);
    throw;
  }
  pending_.clear();
}

void AppendFile::datasync() {
  if (fd_ >= 0 && ::fdatasync(fd_) != 0) fail(path_, "fdatasync", errno);
}

void AppendFile::close() {
  if (fd_ < 0) return;
  sync();
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0) fail(path_, "close", errno);
}

}  // namespace lumar::capture
