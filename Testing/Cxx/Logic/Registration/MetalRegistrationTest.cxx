// Registration with metal in the X-rays: the small phantom's simulated views get two steel K-wires through the bone
// (each a 3D segment projected into every view, attenuating the detector signal by exp(-4.5) over a 5 px wide line).
// With the metal mask (default) the fast preset still recovers the pose from 10 mm; without it the wires pull the
// whole-image NCC and the dynamic ROIs away.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "Registration/Registration.h"
#include "RegistrationTestCase.h"
#include "Simulation/PhantomBuilder.h"

namespace {

/// Distance in pixels from `uv` to the segment a-b.
double distanceToSegment(const Eigen::Vector2d& uv, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((uv - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (uv - (a + t * ab)).norm();
}

/// Burns K-wires (world segments) into every view's intensities: I *= exp(-wireLineIntegral) within 2 px.
void addKWires(fct::test::KnownTruthCase& c, const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& wires) {
  constexpr double kWireLineIntegral = 4.5;
  for (fct::RegistrationView& view : c.views) {
    for (const auto& [a_world_mm, b_world_mm] : wires) {
      const Eigen::Vector2d a_px = view.camera.project(a_world_mm);
      const Eigen::Vector2d b_px = view.camera.project(b_world_mm);
      for (int row = 0; row < view.xray.rows; ++row) {
        for (int col = 0; col < view.xray.cols; ++col) {
          if (distanceToSegment(Eigen::Vector2d(col, row), a_px, b_px) <= 2.0) {
            view.xray.pixels[static_cast<std::size_t>(row) * view.xray.cols + col] *=
                static_cast<float>(std::exp(-kWireLineIntegral));
          }
        }
      }
    }
  }
}

/// Mean bone-surface error in mm after a fast-preset registration from 10 mm, with or without the metal mask.
double errorAfterRegistration(bool excludeMetal) {
  fct::PhantomOptions phantom;
  phantom.dims = Eigen::Vector3i(80, 80, 60);
  phantom.spacing_mm = 2.0;
  auto simulated = fct::test::simulateCase(fct::PhantomBuilder::build(phantom).value());
  EXPECT_TRUE(simulated.ok()) << simulated.error();
  if (!simulated) return 1e9;
  fct::test::KnownTruthCase c = std::move(simulated).value();
  // Two wires through the bone near the world origin (the bone centre and the views' isocentre).
  addKWires(c, {{Eigen::Vector3d(-60.0, -40.0, -30.0), Eigen::Vector3d(50.0, 30.0, 35.0)},
                {Eigen::Vector3d(-30.0, 50.0, 40.0), Eigen::Vector3d(40.0, -45.0, -20.0)}});
  fct::RegistrationCaseOptions caseOptions;
  caseOptions.preparation.excludeMetal = excludeMetal;
  auto registrationCase = fct::RegistrationCase::create(c.ct, c.views, caseOptions);
  EXPECT_TRUE(registrationCase.ok()) << registrationCase.error();
  if (!registrationCase) return 1e9;
  fct::RegistrationCase& rc = registrationCase.value();
  for (std::size_t v = 0; v < rc.viewCount(); ++v) {
    std::printf("view %s: metal fraction %.2f %%\n", rc.viewName(v).c_str(), 100.0 * rc.prepared(v).metalFraction);
    if (excludeMetal) {
      EXPECT_GT(rc.prepared(v).metalFraction, 0.005) << rc.viewName(v);
    }
  }
  const Eigen::Isometry3d start = fct::test::startPose(rc, c.T_truth, 10.0, 1000);
  fct::RegistrationOptions options;
  options.schedule = fct::RegistrationSchedule::builtin("fast").value();
  options.seed = 1000;
  auto result = fct::Registration::run(rc, start, options);
  EXPECT_TRUE(result.ok()) << result.error();
  if (!result) return 1e9;
  const double error = rc.bone()->meanDistance_mm(result.value().T_world_from_ct, c.T_truth);
  std::printf("metal mask %s: error %.3f mm after %ld DRRs\n", excludeMetal ? "on" : "off", error,
              result.value().totalDrrs);
  return error;
}

}  // namespace

TEST(MetalRegistration, PhantomWithKWiresConvergesWithMetalMask) {
  EXPECT_LT(errorAfterRegistration(true), 0.5);
}

TEST(MetalRegistration, PhantomWithKWiresFailsWithoutMetalMask) {
  EXPECT_GT(errorAfterRegistration(false), 0.5);
}
