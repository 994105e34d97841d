#pragma once
// StudioSession: the session file of FluoroCT Studio (JSON, docs/file-formats.md "Studio session file"): the inputs
// (CT path and series, view file or X-ray files), landmarks, initial pose, ROI parameters, registration options, the
// result history (each a RegistrationResultJson object of RESULT.json with the user's verdict) and the current one,
// the X-ray windows, and the ground truth. The CT and X-rays are referenced by path, not copied. Paths inside the
// session's folder are written relative to it.
// Files are written atomically (temporary file, then rename). Version 3 is written; versions 1 and 2 are read too.
// An autosave file has the same schema plus "autosave_of", the session file it belongs to (may be empty).

#include <filesystem>

#include "Base/Result.h"
#include "Widgets/StudioDocument.h"

namespace fct {

/// Saves and opens session files.
class StudioSession {
 public:
  /// File name suffix of session files.
  static constexpr const char* kSuffix = ".fctsession.json";

  /// Writes the document to `path` atomically, then records it as the document's session file and marks the
  /// document saved. Fails naming the path (document unchanged).
  static Status save(StudioDocument& document, const std::filesystem::path& path);
  /// Writes the document as an autosave file (absolute paths, "autosave_of" = its session file); the document is
  /// not marked saved. Fails naming the path.
  static Status writeAutosave(const StudioDocument& document, const std::filesystem::path& path);
  /// Reads a session (or autosave) file, loads its CT and X-rays, and only then replaces the document's content:
  /// on any failure (bad JSON, a key with a bad value, a missing CT or image) the document is left as it was and the
  /// message names the file and key. A session file leaves the document saved with `path` as its session file; an
  /// autosave file leaves it modified, with the session file it belongs to.
  static Status open(StudioDocument& document, const std::filesystem::path& path);
  /// The session file an autosave file belongs to (empty if none or unreadable).
  static std::filesystem::path autosaveOwner(const std::filesystem::path& autosavePath);
};

}  // namespace fct
