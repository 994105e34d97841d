#pragma once
// FuzzScratch: the RAM folder (under /dev/shm when it exists) where the fuzz entry points write each input for the
// loaders that take a path, with a small case of fixture files made by the project's own writers (a CT, two views
// with images, landmark files) that fuzzed view, landmark-pair and session files may name.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace fct::fuzz {

/// The process's scratch folder and its fixtures.
class FuzzScratch {
 public:
  /// Fixture file names inside folder(): the CT, the view file, its two images, the CT and X-ray landmark files.
  static constexpr const char* kCtFile = "ct.nrrd";
  static constexpr const char* kViewFile = "views.json";
  static constexpr const char* kCtLandmarkFile = "ct.mrk.json";
  static constexpr const char* kImageLandmarkFile = "clicks.json";

  /// The scratch folder of this process ($FCT_FUZZ_SCRATCH if set, else /dev/shm/fluoroct-fuzz-<pid>; created on
  /// first use with its fixtures, removed at a normal exit); aborts with a message when it cannot be made.
  static const std::filesystem::path& folder();
  /// Writes `size` bytes to folder()/name (replacing it) and returns the path; aborts when the write fails.
  static std::filesystem::path write(const std::string& name, const std::uint8_t* data, std::size_t size);
  /// Aborts with `what` when `condition` is false: a loader broke its contract (libFuzzer records the input).
  static void require(bool condition, const char* what);
};

}  // namespace fct::fuzz
