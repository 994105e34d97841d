#pragma once
// AtomicFile: the one way FluoroCT replaces a file. The bytes go to a temporary file beside the target, are flushed
// to disk (fsync), and the temporary file is renamed over the target; the folder is flushed too. A full disk, a
// file-size limit or a crash part-way therefore leaves either the previous file or the new one, never a mix.

#include <filesystem>
#include <initializer_list>
#include <string_view>

#include "Base/Result.h"

namespace fct {

/// Atomic replacement of a whole file (text, JSON, DICOM, images, volumes, caches).
class AtomicFile {
 public:
  /// Writes the concatenated `parts` to `path` atomically. On failure (missing folder, disk full, file-size limit,
  /// rename refused) the temporary file is removed, `path` is left as it was and the message names `path` and the
  /// cause (e.g. "No space left on device").
  static Status write(const std::filesystem::path& path, std::initializer_list<std::string_view> parts);

  /// The bytes of a contiguous array of plain values, as a part for write().
  template <typename T>
  static std::string_view bytesOf(const T* data, std::size_t count) {
    return {reinterpret_cast<const char*>(data), count * sizeof(T)};
  }
};

}  // namespace fct
