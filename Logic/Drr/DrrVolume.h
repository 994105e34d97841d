#pragma once
// DrrVolume: the CT prepared once for DRR rendering: per-voxel values whose line integral is the DRR
// (attenuation µ in 1/mm, or the raw voxel value), on the CT's voxel grid, with the CT index <-> CT mm maps.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <memory>
#include <mutex>
#include <string_view>
#include <vector>

#include "Base/Result.h"
#include "Image/Volume.h"

namespace fct {

/// What a DRR integrates along each ray.
enum class DrrValueKind {
  /// µ = µ_water · (1 + HU / 1000) in 1/mm up to DrrValueOptions::kBoneFrom_hu, with the part above it times k (the
  /// bone contrast, DrrValueOptions::boneContrast); HU <= -1000 (air and below) clamped to 0; the DRR ∫µ dl is
  /// dimensionless.
  Attenuation,
  /// The voxel value as stored (HU for a CT, negative in air); the DRR ∫value dl is in value·mm.
  Raw,
};

/// How voxel values become DRR values.
struct DrrValueOptions {
  /// Linear attenuation coefficient of water at 60 keV, the effective energy of a ~100-120 kVp fluoroscopy beam:
  /// µ/ρ = 0.2059 cm²/g (NIST XCOM / Hubbell & Seltzer, NIST Standard Reference Database 126, liquid water), ρ = 1 g/cm³.
  static constexpr double kWaterAttenuationAt60keV_per_mm = 0.02059;

  /// The largest bone contrast accepted: beyond it the CT's bone would outweigh everything else in a DRR.
  static constexpr double kMaxBoneContrast = 10.0;
  /// CT values above this are water-bone mixtures; soft tissues (about -100 to +100 HU) and fat are water-like.
  static constexpr double kBoneFrom_hu = 100.0;
  /// Whether `contrast` is an accepted bone contrast: above 0 and at most kMaxBoneContrast (NaN is not).
  static constexpr bool acceptsBoneContrast(double contrast) { return contrast > 0.0 && contrast <= kMaxBoneContrast; }

  DrrValueKind kind = DrrValueKind::Attenuation;
  double waterAttenuation_per_mm = kWaterAttenuationAt60keV_per_mm;  ///< µ_water used by Attenuation
  /// The attenuation a CT value adds above kBoneFrom_hu (water-bone mixtures) is scaled by this factor, in
  /// (0, kMaxBoneContrast]. A CT measures attenuation at its own beam's energy; at a softer beam's, bone's excess over
  /// water is larger (calcium's photoelectric absorption), while water-like tissue scales with water: the bilinear HU
  /// scaling of CT-based attenuation correction. 1: the CT's own contrast.
  double boneContrast = 1.0;
};

/// What a CT slice's value stands for along the slice axis (k), for a renderer that interpolates between slices.
enum class CtSliceModel {
  /// The patient's value at the slice's centre (the values are interpolated as they are).
  Samples,
  /// The patient's average over the slice's thickness, a box of one slice spacing (contiguous slices, as a CT
  /// reconstructs them): the values are first re-expressed so that their linear interpolant has these averages. Taken
  /// only for a CT of thick slices (DrrVolume::hasThickSlices); near-cubic voxels, as a resampled volume has, are read
  /// as samples (measured: docs/evaluation.md, "Slice profile").
  SlabAverages,
};

/// The per-voxel DRR values of a CT (float, i fastest) and its geometry. Voxel (i,j,k) is the box of one spacing
/// around its centre, so the volume's extent in index space is [-0.5, dims - 0.5] per axis.
class DrrVolume {
 public:
  DrrVolume() = default;

  /// Converts a CT once into a new grid. Fails on an empty volume, non-finite voxels, a non-positive or non-finite
  /// µ_water, or a bone contrast outside (0, kMaxBoneContrast].
  static Result<DrrVolume> create(const Volume& ct, const DrrValueOptions& options = {});
  /// As above, converting the CT's own voxels in place (no second copy of a large CT); `ct` is consumed.
  static Result<DrrVolume> create(Volume&& ct, const DrrValueOptions& options = {});

  /// The values box-averaged over blocks of blockSize_ijk voxels (each >= 1): coarse voxel (I,J,K) is the mean of
  /// voxels [I·b, I·b + b - 1] per axis, where voxels beyond the volume count as 0 (air for attenuation values), so
  /// the coarse grid covers the volume rounded up to whole blocks. Same options and frame; spacing times the block.
  /// A line integral through the result equals one through the original CT blurred by the block (less traversal
  /// work: the coarse pyramid levels of registration use it). Fails on a block size below 1.
  Result<DrrVolume> coarsened(const Eigen::Vector3i& blockSize_ijk) const;

  /// The values re-expressed for a CT whose slices are averages over their thickness (CtSliceModel::SlabAverages):
  /// per (i,j) column, the values c' whose linear interpolant along k averages, over each slice's box of one spacing,
  /// to that slice's value c, i.e. the solution of c_k = c'_{k-1} / 8 + 3 c'_k / 4 + c'_{k+1} / 8 with the outer
  /// slices' neighbours mirrored (the edge value held to the box face, as the trilinear renderer holds it). A
  /// trilinear DRR of the result then integrates the same slice averages as the CT but no longer blurs each slab edge
  /// over two slices. Sharpens along k only (values may dip below 0 beside an edge); same options and geometry.
  DrrVolume sliceAveragesDeconvolved() const;
  /// Slices this many times the larger in-plane spacing, or thicker, count as thick (hasThickSlices).
  static constexpr double kThickSliceRatio = 1.5;
  /// True when the slice spacing (k) is at least kThickSliceRatio times the larger of the i and j spacings: a scan's
  /// own thick slices, each an average over its thickness, rather than a near-cubic resampled grid.
  bool hasThickSlices() const {
    const Eigen::Vector3d& s = m_values.spacing_mm();
    return s.z() >= kThickSliceRatio * std::max(s.x(), s.y());
  }

  /// Parses "attenuation" or "raw"; the error lists the accepted names.
  static Result<DrrValueKind> parseValueKind(std::string_view name);
  /// The name parseValueKind() accepts for `kind`.
  static std::string_view valueKindName(DrrValueKind kind);

  /// The DRR values on the CT grid: 1/mm for Attenuation, the CT's unit for Raw. Geometry equals the CT's.
  const Volume& values() const { return m_values; }
  /// Which values were computed and with which µ_water.
  const DrrValueOptions& options() const { return m_options; }
  /// Voxel count along i, j, k.
  const Eigen::Vector3i& dims() const { return m_values.dims(); }
  /// Contiguous voxel values, i fastest, then j, then k.
  const float* data() const { return m_values.voxels().data(); }
  /// The same values with j fastest, then i, then k (value (i,j,k) at j + nj·(i + ni·k)): the layout in which rays
  /// running along i read neighbouring j contiguously (SiddonRayCaster's packets). Made on the first call (one more
  /// copy of the values in memory), then shared by every renderer and copy of this volume; thread-safe.
  const float* valuesJFastest() const;
  /// Map from CT physical mm (LPS) to continuous voxel index.
  const Eigen::Affine3d& T_ijk_from_ct() const { return m_T_ijk_from_ct; }
  /// Map from continuous voxel index to CT physical mm (LPS).
  const Eigen::Affine3d& T_ct_from_ijk() const { return m_T_ct_from_ijk; }
  /// Lower corner of the voxel boxes in index space: (-0.5, -0.5, -0.5).
  Eigen::Vector3d boxMin_ijk() const { return Eigen::Vector3d::Constant(-0.5); }
  /// Upper corner of the voxel boxes in index space: dims - 0.5.
  Eigen::Vector3d boxMax_ijk() const { return dims().cast<double>().array() - 0.5; }
  /// True when at least one value is non-zero (otherwise every DRR is zero).
  bool hasContent() const { return (m_contentFirst_ijk.array() <= m_contentLast_ijk.array()).all(); }
  /// Lower corner, in index space, of the smallest box of whole voxels holding every non-zero value (air is 0 in
  /// attenuation values, so this is usually the patient, not the scan field); only meaningful when hasContent().
  Eigen::Vector3d contentBoxMin_ijk() const { return m_contentFirst_ijk.cast<double>().array() - 0.5; }
  /// Upper corner of that box in index space.
  Eigen::Vector3d contentBoxMax_ijk() const { return m_contentLast_ijk.cast<double>().array() + 0.5; }

 private:
  /// Checks the options and sets everything but the values from `ct`'s geometry; the error says what is wrong.
  static Result<DrrVolume> prepare(const Volume& ct, const DrrValueOptions& options);
  /// Writes the DRR value of every voxel of `hu` (the CT's values; may be the values' own storage) into the values,
  /// then finds the content box. Fails on non-finite voxels.
  Status convertFrom(const std::vector<float>& hu);
  /// Sets the content box from the values.
  void findContentBox();

  /// The j-fastest copy, made once on demand.
  struct JFastestCopy {
    std::once_flag made;
    std::unique_ptr<float[]> values;
  };

  Volume m_values;
  std::shared_ptr<JFastestCopy> m_jFastest = std::make_shared<JFastestCopy>();
  DrrValueOptions m_options;
  Eigen::Affine3d m_T_ijk_from_ct = Eigen::Affine3d::Identity();
  Eigen::Affine3d m_T_ct_from_ijk = Eigen::Affine3d::Identity();
  Eigen::Vector3i m_contentFirst_ijk = Eigen::Vector3i::Zero();       ///< first voxel index of the content box
  Eigen::Vector3i m_contentLast_ijk = Eigen::Vector3i::Constant(-1);  ///< last voxel index (first > last: none)
};

}  // namespace fct
