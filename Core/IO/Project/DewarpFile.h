#pragma once
// DewarpFile: the image-intensifier dewarp of a C-arm (JSON, written by `fluoroct dewarp-calibrate`, named by a
// view's "dewarp" key):
//   {"format": "fluoroct-dewarp", "version": 1, "image_size": [cols, rows], "model": "polynomial", "degree": n,
//    "centre_px": [cx, cy], "radius_px": R, "terms": [[p, q], ...],
//    "col_coefficients_px": [...], "row_coefficients_px": [...], "calibration": {...}}
// The coefficients define DewarpField (distorted -> ideal pixels); "calibration" records how the field was made
// (grid image, pitch, beads, residuals) and is kept for people, not read back into the field.

#include <filesystem>
#include <string>

#include "Base/Result.h"
#include "Geometry/DewarpField.h"

namespace fct {

/// How a dewarp field was calibrated, as the file records it.
struct DewarpCalibration {
  std::string gridImage;              ///< the calibration grid image's file name
  double pitch_mm = 0.0;              ///< the grid's bead pitch on the plate
  double latticePitch_px = 0.0;       ///< the fitted ideal lattice's pitch in ideal pixels
  double latticeRotation_deg = 0.0;   ///< rotation of the lattice's first axis from +column
  double magnification = 0.0;         ///< lattice pitch × pixel spacing / pitch (0 when the spacing is unknown)
  int beadCount = 0;                  ///< beads used in the fit
  int rejectedBeadCount = 0;          ///< beads found but left out of the fit as outliers
  double rmsResidual_px = 0.0;        ///< RMS of |field(bead) − lattice point| over the beads used
  double maxResidual_px = 0.0;        ///< largest such residual
};

/// A dewarp file's contents.
struct DewarpFileContents {
  DewarpField field;
  DewarpCalibration calibration;
};

/// Reads and writes dewarp files.
class DewarpFile {
 public:
  /// Newest file version this program writes and reads.
  static constexpr int kVersion = 1;

  /// Reads a dewarp file. Fails naming the file and key on bad JSON, another format or a newer version, a model other
  /// than "polynomial", terms that do not match the degree, a centre or radius that is not the image size's, or
  /// coefficients that are missing or not finite. Unknown keys are warnings.
  static Result<DewarpFileContents> read(const std::filesystem::path& path);

  /// Writes the field and its calibration record atomically. Fails on an unwritable path.
  static Status write(const DewarpFileContents& contents, const std::filesystem::path& path);
};

}  // namespace fct
