#pragma once
// Volume: a CT (or any scalar) volume on a regular grid in the DICOM patient LPS frame, in mm.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Image/DicomIdentity.h"

namespace fct {

/// A scalar volume: voxel values (HU for CT) stored as float, x (i) fastest, then y (j), then z (k).
/// Geometry: p_lps_mm = origin_lps_mm + direction * diag(spacing_mm) * ijk.
class Volume {
 public:
  Volume() = default;

  /// Allocates dims voxels filled with fill_value; spacing in mm, origin in LPS mm, direction columns = i, j, k axes in LPS.
  /// Returns an error for non-positive dims/spacing or a direction that is not a rotation (orthonormal, det +1 or -1).
  static Result<Volume> create(const Eigen::Vector3i& dims, const Eigen::Vector3d& spacing_mm,
                               const Eigen::Vector3d& origin_lps_mm = Eigen::Vector3d::Zero(),
                               const Eigen::Matrix3d& direction_lps = Eigen::Matrix3d::Identity(),
                               float fill_value = 0.0f);
  /// A volume that takes over `voxels` (dims.x*dims.y*dims.z values, i fastest) instead of allocating: the same
  /// geometry checks as create(), and an error when the count does not match dims.
  static Result<Volume> fromVoxels(const Eigen::Vector3i& dims, const Eigen::Vector3d& spacing_mm,
                                   const Eigen::Vector3d& origin_lps_mm, const Eigen::Matrix3d& direction_lps,
                                   std::vector<float> voxels);

  /// Number of voxels along i, j, k.
  const Eigen::Vector3i& dims() const { return m_dims; }
  /// Voxel size along i, j, k in mm.
  const Eigen::Vector3d& spacing_mm() const { return m_spacing_mm; }
  /// LPS position of voxel (0,0,0)'s centre in mm.
  const Eigen::Vector3d& origin_lps_mm() const { return m_origin_lps_mm; }
  /// Unit direction cosines: columns are the i, j, k axes expressed in LPS.
  const Eigen::Matrix3d& direction_lps() const { return m_direction_lps; }

  /// Affine map from continuous voxel index (i,j,k) to LPS mm (includes spacing and direction).
  Eigen::Affine3d T_lps_from_ijk() const;
  /// Inverse of T_lps_from_ijk().
  Eigen::Affine3d T_ijk_from_lps() const;
  /// Continuous index of an LPS point in mm.
  Eigen::Vector3d ijkFromLps(const Eigen::Vector3d& p_lps_mm) const;
  /// LPS point in mm of a continuous index.
  Eigen::Vector3d lpsFromIjk(const Eigen::Vector3d& ijk) const;
  /// LPS centre of the volume's voxel grid in mm.
  Eigen::Vector3d centre_lps_mm() const;

  /// Total voxel count.
  std::size_t voxelCount() const { return m_voxels.size(); }
  /// Linear offset of voxel (i,j,k); no bounds check.
  std::size_t offset(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(m_dims.x()) *
           (static_cast<std::size_t>(j) + static_cast<std::size_t>(m_dims.y()) * static_cast<std::size_t>(k));
  }
  /// Voxel value at (i,j,k); no bounds check.
  float at(int i, int j, int k) const { return m_voxels[offset(i, j, k)]; }
  float& at(int i, int j, int k) { return m_voxels[offset(i, j, k)]; }
  /// Contiguous voxel storage (i fastest).
  const std::vector<float>& voxels() const { return m_voxels; }
  std::vector<float>& voxels() { return m_voxels; }

  /// Minimum and maximum voxel value (0,0 for an empty volume; NaN voxels are skipped).
  std::pair<float, float> valueRange() const;

  /// Free-text provenance: file or series read, resampling done, original scalar type.
  std::string description;
  /// Patient, study, series, frame of reference and slices when read from a DICOM series; empty otherwise.
  std::optional<DicomIdentity> dicom;

 private:
  /// The geometry checks of create() and fromVoxels(); the error says what is wrong.
  static Status checkGeometry(const Eigen::Vector3i& dims, const Eigen::Vector3d& spacing_mm,
                              const Eigen::Vector3d& origin_lps_mm, const Eigen::Matrix3d& direction_lps);

  Eigen::Vector3i m_dims = Eigen::Vector3i::Zero();
  Eigen::Vector3d m_spacing_mm = Eigen::Vector3d::Ones();
  Eigen::Vector3d m_origin_lps_mm = Eigen::Vector3d::Zero();
  Eigen::Matrix3d m_direction_lps = Eigen::Matrix3d::Identity();
  std::vector<float> m_voxels;
};

}  // namespace fct
