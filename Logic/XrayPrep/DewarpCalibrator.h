#pragma once
// DewarpCalibrator: fits an image-intensifier dewarp (DewarpField, distorted -> ideal pixels) to an X-ray of a
// calibration plate with beads on a square grid.
//
// 1. Beads: GridBeadDetector (sub-pixel centroids).
// 2. Lattice indices: the bead nearest the image centre is (0, 0); the pitch is the median nearest-neighbour
//    distance; its neighbours within 30 % of the pitch give the two lattice axes (the first nearest to +column);
//    indices then grow breadth-first: from an indexed bead, each of its four neighbours is predicted by the local
//    step vectors (the last observed steps, so the prediction follows the distortion) and accepted when a bead lies
//    within 30 % of the pitch of the prediction.
// 3. Fit: one linear least-squares problem for the polynomial coefficients and the ideal lattice, a similarity
//    g(i, j) = t + s Rot(θ) (i, j) (scale, rotation, translation), minimising Σ |field(bead) − g(i, j)|². The field
//    has no constant or linear term, so the lattice's similarity is pinned where the distortion is smallest, at the
//    detector centre. Beads whose residual exceeds max(0.5 px, 5 robust sigmas) are dropped once and the fit repeated.
// 4. Degree: unless given, the highest degree (2..7, with at least three equations per unknown) whose 5-fold
//    cross-validated RMS residual (each bead predicted by a fit without it) is within 2 % of the best: degrees that
//    predict left-out beads equally well differ in the truncation error of the polynomial, which the bead centroids'
//    own error (about 0.1 px) hides from the residual, and the higher one has less of it.
// 5. Pitch check: with the pixel spacing known, the lattice pitch × spacing / pitch_mm is the plate's magnification,
//    which must lie within 0.9..1.8 (a plate on the detector face magnifies by about 1.0-1.3).

#include <array>
#include <vector>

#include "Base/Result.h"
#include "Geometry/DewarpField.h"
#include "Image/FloatImage.h"
#include "Image/ValidMask.h"
#include "IO/Project/DewarpFile.h"
#include "XrayPrep/GridBeadDetector.h"

namespace fct {

/// Settings of a dewarp calibration.
struct DewarpCalibrationOptions {
  double pitch_mm = 0.0;          ///< bead pitch on the plate, > 0
  double pixelSpacing_mm = 0.0;   ///< detector pixel size; 0 = unknown (the pitch is then not checked)
  int degree = 0;                 ///< polynomial degree 2..9; 0 = choose by cross-validated residual
  GridBeadOptions beads;          ///< bead detection settings
};

/// One bead of the calibration.
struct DewarpBead {
  Eigen::Vector2d distorted_px;        ///< detected centre in the grid image
  std::array<int, 2> lattice{0, 0};    ///< grid index (i, j) from the centre bead
  Eigen::Vector2d ideal_px;            ///< the fitted lattice's point g(i, j)
  double residual_px = 0.0;            ///< |field(distorted) − ideal|
  bool used = true;                    ///< false when dropped as an outlier
};

/// The fit residuals of one polynomial degree.
struct DewarpDegreeResidual {
  int degree = 0;
  double fitRms_px = 0.0;             ///< RMS residual of the fit over the beads it used
  double crossValidatedRms_px = 0.0;  ///< RMS residual of each bead predicted by the fold that left it out
};

/// The outcome of a calibration.
struct DewarpCalibrationResult {
  DewarpField field;
  DewarpCalibration record;                    ///< everything the dewarp file records (gridImage left empty)
  std::vector<DewarpBead> beads;               ///< every indexed bead
  std::vector<DewarpDegreeResidual> degrees;   ///< the degrees tried (one entry when the degree was given)
  int unindexedBeadCount = 0;                  ///< beads detected but not on the grid reached from the centre
};

/// Calibrates a dewarp from a grid image.
class DewarpCalibrator {
 public:
  explicit DewarpCalibrator(DewarpCalibrationOptions options) : m_options(options) {}

  /// The dewarp of `grid` (MONOCHROME2 intensities, beads dark) among the pixels valid in `mask`. Fails on bad
  /// options; "no grid found" when fewer than 9 beads are detected or the centre bead has no two perpendicular
  /// neighbours; "too few beads" when the indexed beads cannot determine the degree's polynomial; a magnification
  /// outside 0.9..1.8 (wrong pitch or pixel spacing); or a detection error.
  Result<DewarpCalibrationResult> calibrate(const FloatImage& grid, const ValidMask& mask) const;

 private:
  DewarpCalibrationOptions m_options;
};

}  // namespace fct
