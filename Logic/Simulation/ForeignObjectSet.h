#pragma once
// ForeignObjectSet: metal objects that are not in the CT — K-wires, screws, plates (placed near the bone, in the CT
// frame, so they move with it) and calibration-grid spheres (fixed to the C-arm, in the camera frame) — as analytic
// cylinders, boxes and spheres, with exact chord lengths for the simulator's rays.

#include <Eigen/Geometry>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"
#include "Image/Volume.h"
#include "Simulation/Physics/HuMaterialModel.h"
#include "Simulation/Physics/MassAttenuationTable.h"

namespace fct {

/// One analytic object, in the frame of its set (mm).
struct ForeignObject {
  enum class Shape { Cylinder, Box, Sphere };
  std::string kind;                  ///< "kwire", "screw_shaft", "screw_head", "plate", "sphere", "gas_pocket"
  Shape shape = Shape::Sphere;
  Material material = Material::Iron;
  double density_g_per_cm3 = MassAttenuationTable::density_g_per_cm3(Material::Iron);  ///< < 0: removes material
  Eigen::Vector3d a_mm = Eigen::Vector3d::Zero();  ///< cylinder axis start, box or sphere centre
  Eigen::Vector3d b_mm = Eigen::Vector3d::Zero();  ///< cylinder axis end
  double radius_mm = 0.0;                           ///< cylinder or sphere radius
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();   ///< box: columns are its unit axes
  Eigen::Vector3d halfExtent_mm = Eigen::Vector3d::Zero();  ///< box: half sizes along its axes
};

/// Settings of the objects placed near the bone.
struct ImplantOptions {
  int kwireCount = 0;
  int screwCount = 0;
  bool plate = false;
  int gasPocketCount = 0;           ///< soft-tissue change: bowel-gas pockets (spheres of r 8-20 mm) in soft tissue near the bone
  double boneThreshold_hu = 300.0;  ///< voxels at or above are bone
  std::uint32_t seed = 1;           ///< drives the placement
};

/// A set of analytic objects in one frame.
class ForeignObjectSet {
 public:
  /// K-wires, screws and a plate near the bone of `ct`, in CT LPS mm: each at a random bone-surface voxel (a bone
  /// voxel with a non-bone 6-neighbour) among the half of them nearest the bone centroid; K-wires point outward (from the bone centroid, ±30° random), tip 25 mm inside;
  /// screws point inward with their head on the surface; the plate lies on the surface, long axis along the CT's
  /// k axis. Gas pockets replace water-density tissue by gas (−1 g/cm³ of soft tissue along their chord) and sit in
  /// soft tissue (every sampled point of the sphere between −200 and 300 HU) within 100 mm of the bone centroid.
  /// Deterministic for a seed. Fails on counts outside 0..20, or when objects are requested on a CT without bone or
  /// gas pockets find no room.
  static Result<ForeignObjectSet> placeNearBone(const Volume& ct, const ImplantOptions& options);

  /// A calibration grid of steel spheres in the camera frame of `camera` (source at the origin, +z toward the
  /// detector): a square grid of pitch spacing_mm on the plane z = SID − distanceFromDetector_mm, centred on the
  /// principal ray, keeping the spheres whose shadow lies fully on the detector. Fails on non-positive sizes or a
  /// plane not between source and detector.
  static Result<ForeignObjectSet> calibrationGrid(const Camera& camera, double spacing_mm, double radius_mm,
                                                  double distanceFromDetector_mm);

  /// Adds every object's mass per area (g/cm², negative for gas pockets) along the ray from `origin_mm` in unit
  /// direction `direction` (the set's frame) at t >= 0 to `paths`.
  void accumulate(const Eigen::Vector3d& origin_mm, const Eigen::Vector3d& direction, MassPaths& paths) const;

  /// The objects.
  const std::vector<ForeignObject>& objects() const { return m_objects; }
  /// The objects as JSON (kind, material, geometry in mm), for simulation.json.
  nlohmann::ordered_json toJson() const;

 private:
  std::vector<ForeignObject> m_objects;
};

}  // namespace fct
