#pragma once
// TextFile: whole-file text reads and atomic writes (temporary file in the same folder, then rename), so a failed
// or interrupted write never leaves a half-written file behind.

#include <filesystem>
#include <string>

#include "Base/Result.h"

namespace fct {

/// Reading and atomically writing small text files (view files, poses, landmarks, transforms).
class TextFile {
 public:
  /// The whole content of a file. Fails with a message naming the path if it is missing, a folder or unreadable.
  static Result<std::string> read(const std::filesystem::path& path);

  /// Writes `contents` to `path` with AtomicFile: on any failure `path` is left as it was and the message names the
  /// path and the cause.
  static Status writeAtomically(const std::filesystem::path& path, const std::string& contents);
};

}  // namespace fct
