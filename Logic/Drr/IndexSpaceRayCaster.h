#pragma once
// IndexSpaceRayCaster: the part shared by the ray casters that integrate each ray in the CT's voxel index frame
// (SiddonRayCaster, TrilinearRayCaster): physical segments and detector pixels are mapped to index space once per
// ray, then Derived::integrateIjk(a_ijk, b_ijk, length_mm) does the per-ray work. CRTP, so no virtual call per ray.

#include <Eigen/Core>
#include <memory>

#include "Drr/DrrRayGeometry.h"
#include "Drr/DrrRenderer.h"

namespace fct {

/// Base of the index-space ray casters; Derived provides
/// `double integrateIjk(const Eigen::Vector3d& a_ijk, const Eigen::Vector3d& b_ijk, double length_mm) const`.
template <typename Derived>
class IndexSpaceRayCaster : public DrrRenderer {
 public:
  /// Line integral of the volume's values along the segment from_ct_mm -> to_ct_mm (CT frame, LPS mm): dimensionless
  /// for attenuation values, value·mm for raw values; 0 if the segment misses the volume.
  double integrate(const Eigen::Vector3d& from_ct_mm, const Eigen::Vector3d& to_ct_mm) const {
    const Eigen::Affine3d& T = volume().T_ijk_from_ct();
    return derived().integrateIjk(T * from_ct_mm, T * to_ct_mm, (to_ct_mm - from_ct_mm).norm());
  }

 protected:
  using DrrRenderer::DrrRenderer;

  DrrRenderStats integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct,
                                 const std::int32_t* pixels, std::size_t count, float* values) const override {
    const DrrRayGeometry geometry(levelCamera, T_world_from_ct, volume().T_ijk_from_ct());
    geometry.integratePixels(pixels, count, values,
                             [this](const Eigen::Vector3d& a, const Eigen::Vector3d& b, double length_mm) {
                               return derived().integrateIjk(a, b, length_mm);
                             });
    return {};
  }

 private:
  const Derived& derived() const { return static_cast<const Derived&>(*this); }
};

}  // namespace fct
