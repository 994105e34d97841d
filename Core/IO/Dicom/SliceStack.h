#pragma once
// SliceStack: parallel 2D image slices at arbitrary positions (irregular gaps, or origins shifted in-plane as in a
// gantry-tilted CT), with the measurements and the resampling that turn them into a regular Volume. LPS, mm.

#include <Eigen/Core>
#include <vector>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// How the slice origins of a SliceStack deviate from a regular grid along the slice normal.
struct SliceStackLayout {
  double minGap_mm = 0.0;           ///< smallest distance between neighbouring slices along the normal
  double maxGap_mm = 0.0;           ///< largest distance between neighbouring slices along the normal
  double meanGap_mm = 0.0;          ///< (last − first position along the normal) / (slices − 1)
  double tilt_deg = 0.0;            ///< angle between the slice normal and the first→last slice origin step
  double maxInPlaneShift_mm = 0.0;  ///< largest in-plane offset of a slice origin from the normal through the first
  bool uniformSpacing = true;       ///< all gaps agree within 1 % of the mean gap (at least 0.01 mm, IPP rounding)
  bool alongNormal = true;          ///< every in-plane shift is below a tenth of a pixel (no gantry tilt)
  /// True when the slices can be stacked into a Volume as they are.
  bool isRegular() const { return uniformSpacing && alongNormal; }
};

/// Equally sized slices of float pixels (i along the row cosine, fastest; j along the column cosine), all with the
/// same orientation, ordered by strictly increasing position along the normal = rowCosine × columnCosine.
class SliceStack {
 public:
  SliceStack() = default;

  /// Allocates origins.size() slices of size_px = (columns, rows) pixels filled with 0. pixelSpacing_mm is the spacing
  /// along i (between columns) and j (between rows); cosines are LPS unit vectors; origins (LPS mm, centre of pixel
  /// (0,0) of each slice) must be strictly increasing along the normal. Errors: empty stack, bad sizes or spacing,
  /// non-orthonormal cosines, unordered or coincident slices.
  static Result<SliceStack> create(const Eigen::Vector2i& size_px, const Eigen::Vector2d& pixelSpacing_mm,
                                   const Eigen::Vector3d& rowCosine_lps, const Eigen::Vector3d& columnCosine_lps,
                                   std::vector<Eigen::Vector3d> sliceOrigins_lps_mm);

  /// Smallest distance along the normal, in mm, that create() accepts between neighbouring slices.
  static constexpr double kMinGap_mm = 1e-3;

  /// Number of slices.
  int sliceCount() const { return static_cast<int>(m_origins_lps_mm.size()); }
  /// Slice size in pixels: (columns, rows).
  const Eigen::Vector2i& size_px() const { return m_size_px; }
  /// Pixel spacing in mm along i (row cosine) and j (column cosine).
  const Eigen::Vector2d& pixelSpacing_mm() const { return m_pixelSpacing_mm; }
  /// Unit slice normal in LPS: rowCosine × columnCosine.
  Eigen::Vector3d normal_lps() const { return m_rowCosine_lps.cross(m_columnCosine_lps); }
  /// LPS position in mm of pixel (0,0) of each slice.
  const std::vector<Eigen::Vector3d>& sliceOrigins_lps_mm() const { return m_origins_lps_mm; }
  /// Pixels of slice k (columns × rows, i fastest); no bounds check.
  float* slice(int k) { return m_pixels.data() + sliceOffset(k); }
  const float* slice(int k) const { return m_pixels.data() + sliceOffset(k); }
  /// Smallest and largest pixel value over all slices.
  std::pair<float, float> valueRange() const;

  /// Gaps, tilt and in-plane shifts of the slice origins.
  SliceStackLayout layout() const;

  /// The slices as a Volume without interpolation: origin = first slice origin, spacing (di, dj, mean gap), direction
  /// (row cosine, column cosine, normal). Error when layout() is not regular (resample instead). Moves the pixels out.
  Result<Volume> toVolume() &&;

  /// Resamples onto a regular orthogonal grid: i, j along the slices' row and column cosines at the slices' pixel
  /// spacing, k along the normal every sliceSpacing_mm from the first slice; the in-plane extent covers every slice.
  /// Each voxel is interpolated linearly between the two neighbouring slices at its physical position (bilinear
  /// within each slice); positions outside a slice take outside_value. Error for a non-positive spacing or a grid
  /// too large to allocate.
  Result<Volume> resampled(double sliceSpacing_mm, float outside_value) const;

 private:
  std::size_t sliceOffset(int k) const {
    return static_cast<std::size_t>(k) * static_cast<std::size_t>(m_size_px.x()) * static_cast<std::size_t>(m_size_px.y());
  }

  Eigen::Vector2i m_size_px = Eigen::Vector2i::Zero();
  Eigen::Vector2d m_pixelSpacing_mm = Eigen::Vector2d::Ones();
  Eigen::Vector3d m_rowCosine_lps = Eigen::Vector3d::UnitX();
  Eigen::Vector3d m_columnCosine_lps = Eigen::Vector3d::UnitY();
  std::vector<Eigen::Vector3d> m_origins_lps_mm;
  std::vector<float> m_pixels;
};

}  // namespace fct
