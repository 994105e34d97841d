#pragma once
// ViewFile: the C-arm view file (JSON) listing each view's image, detector and calibrated camera.
// See README "View file" for the schema. Image paths are relative to the view file's folder.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"
#include "Geometry/PixelCircle.h"

namespace fct {

/// One C-arm view: its name, its image on disk (optional) and its calibrated camera.
struct ViewSpec {
  std::string name;
  std::filesystem::path imagePath;  ///< empty if none; absolute after read
  int frame = 0;                    ///< frame of a multi-frame image file
  Camera camera;
  std::vector<PixelCircle> calibrationSpheres;  ///< shadows of calibration-grid spheres, masked out of the comparison
  std::filesystem::path dewarpPath;  ///< the view's dewarp file (DewarpFile); empty if none; absolute after read
  bool mirrorColumns = false;  ///< flip the image left-right on load (a DICOM stored mirrored against the camera)
};

/// Reads and writes view files.
class ViewFile {
 public:
  /// Reads and validates a view file; image paths come back absolute. Fails with a message naming the file, the
  /// view and the key (bad JSON with line and column, NaN, non-rotation, zero-sized detector, missing image, ...).
  /// Unknown keys are ignored with a warning on the Result.
  static Result<std::vector<ViewSpec>> read(const std::filesystem::path& path);

  /// Writes the views (camera as T_world_from_camera + intrinsics) atomically. Image paths inside the file's folder
  /// are written relative to it, others absolute (a relative imagePath is taken relative to the current folder).
  /// Fails on an empty list, empty or duplicate names, an invalid camera (e.g. default-constructed), or an
  /// unwritable path.
  static Status write(const std::vector<ViewSpec>& views, const std::filesystem::path& path);
};

}  // namespace fct
