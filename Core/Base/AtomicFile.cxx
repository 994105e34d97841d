#include "Base/AtomicFile.h"

#include <fcntl.h>
#include <fmt/core.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

namespace fct {

namespace {

/// A hidden temporary name beside `path`, unique across threads and processes, keeping the extension.
std::filesystem::path temporaryPathBeside(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path folder = path.parent_path();
  return folder / fmt::format(".{}.tmp-{}-{}{}", path.stem().string(), ::getpid(), counter.fetch_add(1),
                              path.extension().string());
}

/// Writes all of `bytes` to `fd`; the errno text on failure.
Status writeAll(int fd, std::string_view bytes) {
  const char* data = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return fail(std::strerror(errno));
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  return Ok{};
}

/// Writes the parts to a new file at `temp` and flushes it to disk; the errno text on failure.
Status writeNewFile(const std::filesystem::path& temp, std::initializer_list<std::string_view> parts) {
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return fail(std::strerror(errno));
  Status status = Ok{};
  for (std::string_view part : parts) {
    status = writeAll(fd, part);
    if (!status) break;
  }
  if (status && ::fsync(fd) != 0) status = fail(std::strerror(errno));
  if (::close(fd) != 0 && status) status = fail(std::strerror(errno));
  return status;
}

/// Flushes the folder's entry list, so that the rename survives a power cut (best effort: some file systems refuse).
void syncFolder(const std::filesystem::path& folder) {
  const int fd = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

Status AtomicFile::write(const std::filesystem::path& path, std::initializer_list<std::string_view> parts) {
  const std::filesystem::path folder = path.parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(folder.empty() ? std::filesystem::path(".") : folder, ec)) {
    return fail(fmt::format("cannot write '{}': the folder '{}' does not exist; create it first", path.string(),
                            folder.string()));
  }
  const std::filesystem::path temp = temporaryPathBeside(path);
  if (Status written = writeNewFile(temp, parts); !written) {
    std::filesystem::remove(temp, ec);
    return fail(fmt::format("cannot write '{}': {}; check free disk space and that the folder is writable (the "
                            "previous file, if any, is unchanged)",
                            path.string(), written.error()));
  }
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    return fail(fmt::format("cannot replace '{}': {}", path.string(), ec.message()));
  }
  syncFolder(folder);
  return Ok{};
}

}  // namespace fct
