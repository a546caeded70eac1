#include "immerse/io/AtomicFile.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "immerse/core/Error.hpp"

namespace immerse::io {

namespace {

// fsync a file or directory by name; returns 0 or errno.
int fsync_path(const std::filesystem::path& p, int flags) {
  const int fd = ::open(p.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return errno;
  const int rc = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return rc;
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path final_path) : path_(std::move(final_path)) {
  temp_ = path_;
  temp_ += ".tmp." + std::to_string(::getpid());
}

AtomicFile::~AtomicFile() {
  if (!committed_) ::unlink(temp_.c_str());
}

void AtomicFile::fail(int err) { fail(std::strerror(err)); }

void AtomicFile::fail(const std::string& why) {
  ::unlink(temp_.c_str());
  committed_ = true;  // nothing left to clean up
  throw WriteError("cannot write " + path_.string() + ": " + why);
}

void AtomicFile::commit() {
  if (int err = fsync_path(temp_, O_RDONLY)) fail(err);
  if (::rename(temp_.c_str(), path_.c_str()) != 0) fail(errno);
  committed_ = true;
  const auto dir = path_.parent_path().empty() ? std::filesystem::path(".") : path_.parent_path();
  // The rename is done; a directory that cannot be synced (some file systems refuse) is not an error.
  fsync_path(dir, O_RDONLY | O_DIRECTORY);
}

void AtomicFile::write(const std::filesystem::path& path, std::string_view contents) {
  AtomicFile f(path);
  const int fd = ::open(f.temp_path().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) f.fail(errno);
  const char* p = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      f.fail(err);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    f.fail(err);
  }
  if (::close(fd) != 0) f.fail(errno);
  f.commit();
}

}  // namespace immerse::io
