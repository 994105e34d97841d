#include <gtest/gtest.h>

#include "Simulation/ForeignObjectSet.h"
#include "Simulation/PhantomBuilder.h"

namespace {
constexpr int kIron = static_cast<int>(fct::Material::Iron);
constexpr int kTitanium = static_cast<int>(fct::Material::Titanium);
constexpr double kIronDensity = fct::MassAttenuationTable::density_g_per_cm3(fct::Material::Iron);

fct::Volume phantom() {
  fct::PhantomOptions options;
  options.dims = Eigen::Vector3i(40, 40, 30);
  options.spacing_mm = 4.0;
  return fct::PhantomBuilder::build(options).value();
}

/// An 8^3 volume of 2 mm voxels, all of one value (HU).
fct::Volume uniformVolume(float value_hu) {
  return fct::Volume::create(Eigen::Vector3i(8, 8, 8), Eigen::Vector3d::Constant(2.0), Eigen::Vector3d::Zero(),
                             Eigen::Matrix3d::Identity(), value_hu)
      .value();
}

}  // namespace

TEST(ForeignObjectSet, GridSpheresGiveExactChordsAndProjectOntoTheDetector) {
  const fct::Camera camera =
      fct::Camera::lookingAt(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), 800.0, 1000.0, 200, 150, 1.0);
  auto grid = fct::ForeignObjectSet::calibrationGrid(camera, 30.0, 2.0, 100.0);
  ASSERT_TRUE(grid.ok()) << grid.error();
  ASSERT_GE(grid.value().objects().size(), 9u);
  for (const fct::ForeignObject& sphere : grid.value().objects()) {
    EXPECT_DOUBLE_EQ(sphere.a_mm.z(), 900.0);
    const Eigen::Vector3d uvw = camera.K() * sphere.a_mm;
    EXPECT_GT(uvw.x() / uvw.z(), 0.0);
    EXPECT_LT(uvw.x() / uvw.z(), 199.0);
  }
  // The ray from the source through a sphere centre crosses its diameter.
  const fct::ForeignObject& first = grid.value().objects().front();
  fct::MassPaths paths{};
  grid.value().accumulate(Eigen::Vector3d::Zero(), first.a_mm.normalized(), paths);
  EXPECT_NEAR(paths[kIron], kIronDensity * 0.4, 1e-9);
}

TEST(ForeignObjectSet, PlacesImplantsOnTheBoneDeterministically) {
  const fct::Volume ct = phantom();
  fct::ImplantOptions options;
  options.kwireCount = 2;
  options.screwCount = 1;
  options.plate = true;
  auto placed = fct::ForeignObjectSet::placeNearBone(ct, options);
  ASSERT_TRUE(placed.ok()) << placed.error();
  ASSERT_EQ(placed.value().objects().size(), 5u);  // 2 wires, shaft + head, plate
  auto again = fct::ForeignObjectSet::placeNearBone(ct, options);
  EXPECT_TRUE(again.value().objects()[0].a_mm.isApprox(placed.value().objects()[0].a_mm));
  // A screw shaft starts on a bone-surface voxel; a ray along a K-wire's axis crosses its full length.
  for (const fct::ForeignObject& object : placed.value().objects()) {
    if (object.kind == "screw_shaft") {
      const Eigen::Vector3i ijk = ct.ijkFromLps(object.a_mm).array().round().cast<int>();
      EXPECT_GE(ct.at(ijk.x(), ijk.y(), ijk.z()), 300.0f);
      fct::MassPaths paths{};
      const Eigen::Vector3d axis = (object.b_mm - object.a_mm).normalized();
      placed.value().accumulate(object.a_mm - 10.0 * axis, axis, paths);
      EXPECT_GT(paths[kTitanium], 4.54 * 4.0 - 1e-9);  // 40 mm of titanium at least
    }
  }
  const fct::ForeignObject& wire = placed.value().objects()[0];
  fct::MassPaths paths{};
  placed.value().accumulate(wire.a_mm - 5.0 * (wire.b_mm - wire.a_mm).normalized(), (wire.b_mm - wire.a_mm).normalized(), paths);
  EXPECT_GE(paths[kIron], kIronDensity * 15.0 - 1e-9);
  EXPECT_EQ(placed.value().toJson().size(), 5u);

  // Gas pockets lie in soft tissue and remove tissue mass along their chords.
  fct::ImplantOptions gas;
  gas.gasPocketCount = 2;
  auto pockets = fct::ForeignObjectSet::placeNearBone(ct, gas);
  ASSERT_TRUE(pockets.ok()) << pockets.error();
  ASSERT_EQ(pockets.value().objects().size(), 2u);
  const fct::ForeignObject& pocket = pockets.value().objects()[0];
  EXPECT_EQ(pocket.kind, "gas_pocket");
  const Eigen::Vector3i centre = ct.ijkFromLps(pocket.a_mm).array().round().cast<int>();
  EXPECT_LT(ct.at(centre.x(), centre.y(), centre.z()), 300.0f);
  fct::MassPaths through{};
  pockets.value().accumulate(pocket.a_mm - Eigen::Vector3d(0, 0, 100), Eigen::Vector3d::UnitZ(), through);
  EXPECT_LE(through[static_cast<int>(fct::Material::SoftTissue)], -0.2 * pocket.radius_mm + 1e-9);
}

TEST(ForeignObjectSet, RejectsNoBoneAndBadSizes) {
  const fct::Volume water = uniformVolume(0.0f);
  fct::ImplantOptions options;
  options.kwireCount = 1;
  EXPECT_FALSE(fct::ForeignObjectSet::placeNearBone(water, options).ok());
  options.kwireCount = -1;
  EXPECT_FALSE(fct::ForeignObjectSet::placeNearBone(water, options).ok());
  options.kwireCount = 0;
  options.gasPocketCount = 21;
  EXPECT_FALSE(fct::ForeignObjectSet::placeNearBone(phantom(), options).ok());
  EXPECT_TRUE(fct::ForeignObjectSet::placeNearBone(water, {}).ok());  // nothing asked, nothing needed
  const fct::Camera camera =
      fct::Camera::lookingAt(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), 800.0, 1000.0, 100, 100, 1.0);
  EXPECT_FALSE(fct::ForeignObjectSet::calibrationGrid(camera, 3.0, 2.0, 100.0).ok());
  EXPECT_FALSE(fct::ForeignObjectSet::calibrationGrid(camera, 30.0, 2.0, 1200.0).ok());
}

TEST(ForeignObjectSet, GasPocketsWithoutSoftTissueFailInTheModulesOwnWords) {
  const fct::Volume bone = uniformVolume(1000.0f);
  fct::ImplantOptions options;
  options.gasPocketCount = 1;
  const auto placed = fct::ForeignObjectSet::placeNearBone(bone, options);
  ASSERT_FALSE(placed.ok());
  EXPECT_NE(placed.error().find("no soft tissue near the bone"), std::string::npos) << placed.error();
  EXPECT_NE(placed.error().find("remove the gas pockets"), std::string::npos) << placed.error();
  EXPECT_EQ(placed.error().find("--"), std::string::npos) << "no command-line flag in Logic: " << placed.error();
}
