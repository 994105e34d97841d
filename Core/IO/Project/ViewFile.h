#pragma once
// ViewFile: the C-arm view file (JSON) listing each view's image, detector and calibrated camera.
// See README "View file" for the schema. Image paths are relative to the view file's folder.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"
#include "Geometry/PixelCircle.h"

namespace fct {

/// The frames of a view's fluoroscopy sequence (cine): a range of one multi-frame DICOM file, or a list of image files.
struct ViewSequence {
  std::filesystem::path multiFramePath;      ///< the multi-frame file (absolute after read); empty for the list form
  bool allFrames = true;                     ///< multi-frame form: every frame of the file ("frames": "all")
  int firstFrame = 0;                        ///< multi-frame form: first frame, 0-based
  int lastFrame = 0;                         ///< multi-frame form: last frame, 0-based, inclusive
  std::vector<std::filesystem::path> files;  ///< list form: one image file per frame (absolute after read)

  /// Number of frames.
  int frameCount() const { return multiFramePath.empty() ? static_cast<int>(files.size()) : lastFrame - firstFrame + 1; }
  /// The file and its 0-based frame holding sequence frame i (0 <= i < frameCount(), unchecked).
  std::pair<std::filesystem::path, int> frame(int i) const {
    if (multiFramePath.empty()) return {files[static_cast<std::size_t>(i)], 0};
    return {multiFramePath, firstFrame + i};
  }
};

/// One C-arm view: its name, its image on disk (optional) and its calibrated camera.
struct ViewSpec {
  std::string name;
  std::filesystem::path imagePath;  ///< empty if none; absolute after read; a sequence's first frame when it has one
  int frame = 0;                    ///< frame of a multi-frame image file
  Camera camera;
  std::vector<PixelCircle> calibrationSpheres;  ///< shadows of calibration-grid spheres, masked out of the comparison
  std::filesystem::path dewarpPath;  ///< the view's dewarp file (DewarpFile); empty if none; absolute after read
  bool mirrorColumns = false;  ///< flip the image left-right on load (a DICOM stored mirrored against the camera)
  std::optional<ViewSequence> sequence;  ///< the view's frame sequence ("sequence" instead of "image"), if any
};

/// Reads and writes view files.
class ViewFile {
 public:
  /// Reads and validates a view file; image paths come back absolute. Fails with a message naming the file, the
  /// view and the key (bad JSON with line and column, NaN, non-rotation, zero-sized detector, missing image, ...).
  /// Unknown keys are ignored with a warning on the Result. A view with a "sequence" gets its first frame as
  /// imagePath/frame; fails on a view giving both "image" and "sequence", a frame range outside the file or with
  /// last < first, an empty file list, or views whose sequences differ in frame count (or some views without one).
  static Result<std::vector<ViewSpec>> read(const std::filesystem::path& path);

  /// Writes the views (camera as T_world_from_camera + intrinsics; a view with a sequence as "sequence", not "image")
  /// atomically. Image paths inside the file's folder
  /// are written relative to it, others absolute (a relative imagePath is taken relative to the current folder).
  /// Fails on an empty list, empty or duplicate names, an invalid camera (e.g. default-constructed), or an
  /// unwritable path.
  static Status write(const std::vector<ViewSpec>& views, const std::filesystem::path& path);
};

}  // namespace fct
