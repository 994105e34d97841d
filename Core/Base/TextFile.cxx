#include "Base/TextFile.h"

#include <fcntl.h>
#include <fmt/core.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

namespace fct {

namespace {

/// A temporary name beside `path` that no other writer in this or another process uses.
std::filesystem::path temporaryPathBeside(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path temp = path;
  temp += fmt::format(".tmp-{}-{}", ::getpid(), counter.fetch_add(1));
  return temp;
}

Status writeAll(int fd, const std::string& contents) {
  const char* data = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return fail(std::strerror(errno));
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  if (::fsync(fd) != 0) return fail(std::strerror(errno));
  return Ok{};
}

}  // namespace

Result<std::string> TextFile::read(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return fail(fmt::format("'{}' not found; check the path (a relative path is taken from the current folder)",
                            path.string()));
  }
  if (std::filesystem::is_directory(path, ec)) {
    return fail(fmt::format("'{}' is a folder, not a file", path.string()));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(fmt::format("cannot open '{}' for reading: {}", path.string(), std::strerror(errno)));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return fail(fmt::format("error while reading '{}'", path.string()));
  return text.str();
}

Status TextFile::writeAtomically(const std::filesystem::path& path, const std::string& contents) {
  const std::filesystem::path temp = temporaryPathBeside(path);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    return fail(fmt::format("cannot write '{}': {}; check that the folder exists and is writable", path.string(),
                            std::strerror(errno)));
  }
  const Status written = writeAll(fd, contents);
  const bool closed = ::close(fd) == 0;
  std::error_code ec;
  if (!written || !closed) {
    std::filesystem::remove(temp, ec);
    return fail(fmt::format("cannot write '{}': {}", path.string(),
                            written ? std::string(std::strerror(errno)) : written.error()));
  }
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    return fail(fmt::format("cannot replace '{}': {}", path.string(), ec.message()));
  }
  return Ok{};
}

}  // namespace fct
