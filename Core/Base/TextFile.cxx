#include "Base/TextFile.h"

#include "Base/AtomicFile.h"

#include <fmt/core.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

namespace fct {

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
  return AtomicFile::write(path, {contents});
}

}  // namespace fct
