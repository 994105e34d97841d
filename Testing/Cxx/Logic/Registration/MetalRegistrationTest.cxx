// Registration with metal in the X-rays: the small phantom's simulated views get two steel K-wires through the bone
// (each a 3D segment projected into every view, attenuating the detector signal by exp(-4.5) over a 5 px wide line).
// With the metal mask (default) the fast preset still recovers the pose from 10 mm; without it the wires pull the
// whole-image NCC and the dynamic ROIs away.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "Registration/Registration.h"
#include "RegistrationTestCase.h"
#include "Simulation/PhantomBuilder.h"

namespace {

/// Distance from `p` to the segment a-b (pixels in 2D, mm in 3D).
template <int N>
double distanceToSegment(const Eigen::Matrix<double, N, 1>& p, const Eigen::Matrix<double, N, 1>& a,
                         const Eigen::Matrix<double, N, 1>& b) {
  const Eigen::Matrix<double, N, 1> ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
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

/// Two K-wires through the bone near the world origin (the bone centre and the views' isocentre): world segments, mm.
std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> kWires() {
  return {{Eigen::Vector3d(-60.0, -40.0, -30.0), Eigen::Vector3d(50.0, 30.0, 35.0)},
          {Eigen::Vector3d(-30.0, 50.0, 40.0), Eigen::Vector3d(40.0, -45.0, -20.0)}};
}

/// The phantom case with the two K-wires burnt into its views, prepared with or without the metal mask.
struct KWireCase {
  fct::test::KnownTruthCase truth;
  fct::RegistrationCase registrationCase;
};

/// The phantom case with `wires` (world segments, mm) burnt into its views; `cutFaceMargin_mm` as the case option.
KWireCase prepareKWireCase(bool excludeMetal,
                           const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& wires = kWires(),
                           double cutFaceMargin_mm = -1.0) {
  fct::PhantomOptions phantom;
  phantom.dims = Eigen::Vector3i(80, 80, 60);
  phantom.spacing_mm = 2.0;
  auto simulated = fct::test::simulateCase(fct::PhantomBuilder::build(phantom).value());
  EXPECT_TRUE(simulated.ok()) << simulated.error();
  fct::test::KnownTruthCase c = std::move(simulated).value();
  addKWires(c, wires);
  fct::RegistrationCaseOptions caseOptions;
  caseOptions.preparation.excludeMetal = excludeMetal;
  caseOptions.cutFaceMargin_mm = cutFaceMargin_mm;
  auto registrationCase = fct::RegistrationCase::create(c.ct, c.views, caseOptions);
  EXPECT_TRUE(registrationCase.ok()) << registrationCase.error();
  return KWireCase{std::move(c), std::move(registrationCase).value()};
}

/// Mean bone-surface error in mm after a fast-preset registration from 10 mm, with or without the metal mask, and
/// with or without a metal review before its second stage.
double errorAfterRegistration(bool excludeMetal, bool metalReview = false) {
  KWireCase k = prepareKWireCase(excludeMetal);
  fct::RegistrationCase& rc = k.registrationCase;
  for (std::size_t v = 0; v < rc.viewCount(); ++v) {
    std::printf("view %s: metal fraction %.2f %%\n", rc.viewName(v).c_str(), 100.0 * rc.prepared(v).metalFraction);
    if (excludeMetal) {
      EXPECT_GT(rc.prepared(v).metalFraction, 0.005) << rc.viewName(v);
    }
  }
  const Eigen::Isometry3d start = fct::test::startPose(rc, k.truth.T_truth, 10.0, 1000);
  fct::RegistrationOptions options;
  options.schedule = fct::RegistrationSchedule::builtin("fast").value();
  if (metalReview) options.schedule.stages.at(1).metalReview = true;
  options.seed = 1000;
  auto result = fct::Registration::run(rc, start, options);
  EXPECT_TRUE(result.ok()) << result.error();
  if (!result) return 1e9;
  const double error = rc.bone()->meanDistance_mm(result.value().T_world_from_ct, k.truth.T_truth);
  std::printf("metal mask %s%s: error %.3f mm after %ld DRRs\n", excludeMetal ? "on" : "off",
              metalReview ? " with review" : "", error, result.value().totalDrrs);
  if (metalReview) {
    EXPECT_EQ(result.value().stages.at(1).metalPiecesGivenBack, 0) << "the K-wires are not in the CT";
    for (std::size_t v = 0; v < rc.viewCount(); ++v) EXPECT_GT(rc.prepared(v).metalFraction, 0.005) << rc.viewName(v);
  }
  return error;
}

}  // namespace

TEST(MetalRegistration, PhantomWithKWiresConvergesWithMetalMask) {
  EXPECT_LT(errorAfterRegistration(true), 0.5);
}

TEST(MetalRegistration, PhantomWithKWiresFailsWithoutMetalMask) {
  EXPECT_GT(errorAfterRegistration(false), 0.5);
}

TEST(MetalRegistration, MetalReviewKeepsTheKWiresMaskedAndConverges) {
  EXPECT_LT(errorAfterRegistration(true, true), 0.5);
}

TEST(MetalRegistration, MetalReviewComparesMetalTheCtHolds) {
  // At the truth the review keeps the K-wires, which the CT lacks, out.
  KWireCase k = prepareKWireCase(true);
  fct::RegistrationCase& rc = k.registrationCase;
  std::vector<double> before;
  for (std::size_t v = 0; v < rc.viewCount(); ++v) before.push_back(rc.prepared(v).metalFraction);
  auto unchanged = rc.reviewMetalMasks(k.truth.T_truth);
  ASSERT_TRUE(unchanged.ok()) << unchanged.error();
  EXPECT_EQ(unchanged.value().piecesGivenBack, 0);
  EXPECT_EQ(unchanged.value().drrs, static_cast<int>(rc.viewCount()));
  for (std::size_t v = 0; v < rc.viewCount(); ++v) EXPECT_DOUBLE_EQ(rc.prepared(v).metalFraction, before[v]);

  // Steel-dense rods in the CT itself (an implant already there before surgery): the detector takes their shadows for
  // tools, the DRR explains them, and the review gives them back.
  fct::PhantomOptions phantom;
  phantom.dims = Eigen::Vector3i(80, 80, 60);
  phantom.spacing_mm = 2.0;
  fct::Volume ct = fct::PhantomBuilder::build(phantom).value();
  const Eigen::Vector3d c_ct_mm = ct.centre_lps_mm();
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rods_ct_mm = {
      {c_ct_mm + Eigen::Vector3d(-50.0, -30.0, -25.0), c_ct_mm + Eigen::Vector3d(45.0, 25.0, 30.0)},
      {c_ct_mm + Eigen::Vector3d(-25.0, 45.0, 30.0), c_ct_mm + Eigen::Vector3d(35.0, -40.0, -15.0)}};
  for (const auto& [a_ct_mm, b_ct_mm] : rods_ct_mm) {
    for (int z = 0; z < ct.dims().z(); ++z) {
      for (int y = 0; y < ct.dims().y(); ++y) {
        for (int x = 0; x < ct.dims().x(); ++x) {
          const Eigen::Vector3d p_ct_mm = ct.lpsFromIjk(Eigen::Vector3d(x, y, z));
          if (distanceToSegment(p_ct_mm, a_ct_mm, b_ct_mm) <= 2.0) ct.at(x, y, z) = 60000.0f;  // a steel rod
        }
      }
    }
  }
  auto simulated = fct::test::simulateCase(ct);
  ASSERT_TRUE(simulated.ok()) << simulated.error();
  auto withRods = fct::RegistrationCase::create(simulated.value().ct, simulated.value().views);
  ASSERT_TRUE(withRods.ok()) << withRods.error();
  std::vector<double> rodsBefore;
  for (std::size_t v = 0; v < withRods.value().viewCount(); ++v) {
    rodsBefore.push_back(withRods.value().prepared(v).metalFraction);
    EXPECT_GT(rodsBefore.back(), 0.005) << "the rods look like tools to the detector";
  }
  auto reviewed = withRods.value().reviewMetalMasks(simulated.value().T_truth);
  ASSERT_TRUE(reviewed.ok()) << reviewed.error();
  EXPECT_GE(reviewed.value().piecesGivenBack, 1);
  for (std::size_t v = 0; v < withRods.value().viewCount(); ++v) {
    const double after = withRods.value().prepared(v).metalFraction;
    std::printf("rods in the CT, view %s: metal fraction %.2f %% -> %.2f %%\n", withRods.value().viewName(v).c_str(),
                100.0 * rodsBefore[v], 100.0 * after);
    EXPECT_LT(after, 0.25 * rodsBefore[v]) << withRods.value().viewName(v);
  }
}

TEST(MetalRegistration, MetalFractionOfCoveredFieldCountsOnlyRaysTheCtCovers) {
  // The two K-wires through the bone: on rays the CT covers.
  KWireCase through = prepareKWireCase(true, kWires(), 5.0);
  // A K-wire beyond the phantom's superior face (world z, LPS): the detector masks it, but its rays do not cross the
  // CT, so it takes nothing from the pixels a comparison uses (the phantom's own false positives, in the case without
  // a wire, stay as they are).
  KWireCase noWire = prepareKWireCase(true, {}, 5.0);
  const fct::Volume& ct = through.truth.ct;
  double top_world_mm = -1e9;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d ijk((corner & 1) ? ct.dims().x() - 1 : 0, (corner & 2) ? ct.dims().y() - 1 : 0,
                              (corner & 4) ? ct.dims().z() - 1 : 0);
    top_world_mm = std::max(top_world_mm, (through.truth.T_truth * ct.lpsFromIjk(ijk)).z());
  }
  std::printf("the CT's highest corner at world z %.1f mm\n", top_world_mm);
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> beyondTheSlab = {
      {Eigen::Vector3d(-30.0, -20.0, top_world_mm + 15.0), Eigen::Vector3d(30.0, 20.0, top_world_mm + 25.0)}};
  KWireCase beyond = prepareKWireCase(true, beyondTheSlab, 5.0);
  KWireCase throughNoMargin = prepareKWireCase(true, kWires(), -1.0);
  for (std::size_t v = 0; v < beyond.registrationCase.viewCount(); ++v) {
    const std::string name = beyond.registrationCase.viewName(v);
    const double beyondField = beyond.registrationCase.prepared(v).metalFraction;
    const double noWireField = noWire.registrationCase.prepared(v).metalFraction;
    auto beyondCovered = beyond.registrationCase.metalFractionOfCoveredField(v, beyond.truth.T_truth);
    auto noWireCovered = noWire.registrationCase.metalFractionOfCoveredField(v, noWire.truth.T_truth);
    auto throughCovered = through.registrationCase.metalFractionOfCoveredField(v, through.truth.T_truth);
    auto noMargin = throughNoMargin.registrationCase.metalFractionOfCoveredField(v, throughNoMargin.truth.T_truth);
    ASSERT_TRUE(beyondCovered.ok() && noWireCovered.ok() && throughCovered.ok() && noMargin.ok()) << name;
    std::printf("view %s: no wire %.2f %% of the field, %.2f %% of the covered field; wire beyond the slab %.2f %%, "
                "%.2f %%; wires through the bone %.2f %% of the covered field\n",
                name.c_str(), 100.0 * noWireField, 100.0 * noWireCovered.value(), 100.0 * beyondField,
                100.0 * beyondCovered.value(), 100.0 * throughCovered.value());
    EXPECT_GT(beyondField, noWireField + 0.002) << name << ": the wire beyond the slab is masked";
    EXPECT_DOUBLE_EQ(beyondCovered.value(), noWireCovered.value()) << name;
    EXPECT_GT(throughCovered.value(), noWireCovered.value() + 0.005) << name;
    // Without a cut-face margin every field pixel counts: the whole field's fraction.
    EXPECT_DOUBLE_EQ(noMargin.value(), throughNoMargin.registrationCase.prepared(v).metalFraction) << name;
  }
  EXPECT_FALSE(beyond.registrationCase.metalFractionOfCoveredField(99, beyond.truth.T_truth).ok());
}
