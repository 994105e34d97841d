#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "Drr/DrrVolume.h"
#include "Drr/SiddonRayCaster.h"
#include "Drr/Transgraph.h"
#include "Drr/TransgraphCache.h"
#include "Drr/TransgraphRenderer.h"
#include "Geometry/Camera.h"
#include "Geometry/RigidPose.h"
#include "Image/Volume.h"
#include "TestSupport.h"

namespace {

using fct::Camera;
using fct::Transgraph;
using fct::TransgraphCache;
using fct::TransgraphParameters;
using fct::TransgraphRenderer;

// A uniform ellipsoid with axes along the CT frame's axes; the integral of a segment is its chord length times value.
struct Ellipsoid {
  Eigen::Vector3d centre_ct_mm;
  Eigen::Vector3d semiAxes_mm;
  double value = 1.0;

  // Closed-form chord length (mm) of the segment from -> to inside the ellipsoid, times value.
  double integral(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
    const Eigen::Vector3d a = (from - centre_ct_mm).cwiseQuotient(semiAxes_mm);
    const Eigen::Vector3d d = (to - from).cwiseQuotient(semiAxes_mm);
    const double A = d.squaredNorm(), B = 2.0 * a.dot(d), C = a.squaredNorm() - 1.0;
    const double disc = B * B - 4.0 * A * C;
    if (A <= 0.0 || disc <= 0.0) return 0.0;
    const double root = std::sqrt(disc);
    const double t0 = std::max(0.0, (-B - root) / (2.0 * A)), t1 = std::min(1.0, (-B + root) / (2.0 * A));
    return t1 > t0 ? (t1 - t0) * (to - from).norm() * value : 0.0;
  }
  // Smallest normalized radius reached by the line through from and to (0 = through the centre, 1 = tangent).
  double closestNormalizedRadius(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
    const Eigen::Vector3d a = (from - centre_ct_mm).cwiseQuotient(semiAxes_mm);
    const Eigen::Vector3d d = (to - from).cwiseQuotient(semiAxes_mm).normalized();
    return (a - a.dot(d) * d).norm();
  }
  Transgraph::RayIntegrator integrator() const {
    return [e = *this](const Eigen::Vector3d& from, const Eigen::Vector3d& to) { return e.integral(from, to); };
  }
};

// The shared scene: a 64^3 CT at 2 mm with a tilted direction matrix, an ellipsoid inside, an oblique view.
struct Scene {
  fct::Volume ct;
  Ellipsoid ellipsoid;
  Camera view;
  Eigen::Isometry3d T_expected = Eigen::Isometry3d::Identity();
  TransgraphParameters parameters;

  Scene() {
    const Eigen::Matrix3d direction = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    ct = fct::Volume::create(Eigen::Vector3i(64, 64, 64), Eigen::Vector3d(2.0, 2.0, 2.0),
                             Eigen::Vector3d(-40.0, 25.0, 100.0), direction)
             .value();
    ct.voxels()[1234] = 5.0f;  // content for the cache key
    ellipsoid = Ellipsoid{ct.centre_lps_mm() + Eigen::Vector3d(3.0, -2.0, 1.0), Eigen::Vector3d(46.0, 38.0, 42.0), 0.5};
    T_expected = fct::RigidPose::toTransform(
        fct::PoseParameters{Eigen::Vector3d(5.0, -8.0, 12.0), Eigen::Vector3d(10.0, -20.0, 5.0)}, ct.centre_lps_mm());
    const Eigen::Matrix3d R_world_from_camera =
        (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    view = Camera::lookingAt(T_expected * ct.centre_lps_mm(), R_world_from_camera, 1000.0, 1500.0, 80, 60, 2.4);
    parameters.spacing_mm = 3.0;
    parameters.range.rotation_deg = 6.0;
    parameters.range.translation_mm = 12.0;
    parameters.integratorId = "test-ellipsoid";
  }

  // A pose inside the validity range: the given deviation about the CT centre, applied after the expected pose.
  Eigen::Isometry3d poseWithin(const Eigen::Vector3d& rotation_deg, const Eigen::Vector3d& translation_mm) const {
    const Eigen::Vector3d centre_world = T_expected * ct.centre_lps_mm();
    return fct::RigidPose::toTransform(fct::PoseParameters{rotation_deg, translation_mm}, centre_world) * T_expected;
  }

  // Ray endpoints in the CT frame of pixel (col,row) of `camera` at `pose`.
  static std::pair<Eigen::Vector3d, Eigen::Vector3d> pixelRay(const Camera& camera, const Eigen::Isometry3d& pose,
                                                             int col, int row) {
    const Eigen::Isometry3d T_ct_from_world = pose.inverse();
    return {T_ct_from_world * camera.sourcePosition_world_mm(),
            T_ct_from_world * camera.detectorPoint_world_mm(Eigen::Vector2d(col, row))};
  }
};

// The scene's table, filled with the closed-form integrator, behind the DrrRenderer interface (the volume only
// provides geometry; every value comes from the Transgraph).
const TransgraphRenderer& sceneRenderer() {
  static const Scene scene;
  static const std::unique_ptr<TransgraphRenderer> renderer =
      TransgraphRenderer::fromTransgraph(
          std::make_shared<const fct::DrrVolume>(fct::DrrVolume::create(scene.ct).value()),
          Transgraph::build(scene.ct, scene.view, scene.T_expected, scene.parameters, scene.ellipsoid.integrator())
              .value())
          .value();
  return *renderer;
}

// Checks every pixel whose ray passes through the ellipsoid's interior against the closed form; returns the count.
int expectInteriorPixelsMatch(const Scene& scene, const Camera& camera, const Eigen::Isometry3d& pose,
                              const fct::FloatImage& drr, double relativeTolerance) {
  int checked = 0;
  for (int row = 0; row < drr.rows; ++row) {
    for (int col = 0; col < drr.cols; ++col) {
      const auto [source, end] = Scene::pixelRay(camera, pose, col, row);
      if (scene.ellipsoid.closestNormalizedRadius(source, end) > 0.8) continue;
      const double exact = scene.ellipsoid.integral(source, end);
      EXPECT_NEAR(drr.at(col, row), exact, relativeTolerance * exact) << "pixel (" << col << ", " << row << ")";
      ++checked;
    }
  }
  return checked;
}

TEST(Transgraph, PlansTableAroundTheCtAndReportsSize) {
  const Scene scene;
  const Transgraph& transgraph = sceneRenderer().transgraph();
  const auto& layout = transgraph.layout();
  EXPECT_EQ(transgraph.rayCount(), layout.rayCount());
  EXPECT_EQ(transgraph.memory_bytes(), 4 * layout.rayCount());
  EXPECT_GT(transgraph.buildInfo().build_s, 0.0);
  EXPECT_FALSE(transgraph.buildInfo().loadedFromCache);
  // Every corner of the CT box lies between the planes.
  const Eigen::Matrix3d R_plane_from_ct = layout.R_ct_from_plane.transpose();
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d ijk((corner & 1) ? 63.5 : -0.5, (corner & 2) ? 63.5 : -0.5, (corner & 4) ? 63.5 : -0.5);
    const double w = (R_plane_from_ct * (scene.ct.lpsFromIjk(ijk) - layout.origin_ct_mm)).z();
    EXPECT_GT(w, layout.front_w_mm);
    EXPECT_LT(w, layout.back_w_mm);
  }
  // The w axis is the view's principal direction seen from the CT at the expected pose.
  const Eigen::Vector3d principal_ct =
      scene.T_expected.linear().transpose() * scene.view.T_world_from_camera().linear().col(2);
  EXPECT_NEAR((layout.R_ct_from_plane.col(2) - principal_ct).norm(), 0.0, 1e-12);
  // Planning again gives the same layout; a twice wider range needs a larger table.
  auto again = Transgraph::plan(scene.ct, scene.view, scene.T_expected, scene.parameters);
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_EQ(again.value().counts, layout.counts);
  TransgraphParameters wider = scene.parameters;
  wider.range.rotation_deg *= 2.0;
  wider.range.translation_mm *= 2.0;
  auto widerPlan = Transgraph::plan(scene.ct, scene.view, scene.T_expected, wider);
  ASSERT_TRUE(widerPlan.ok()) << widerPlan.error();
  EXPECT_GT(widerPlan.value().rayCount(), layout.rayCount());
}

TEST(Transgraph, MatchesAnalyticEllipsoidInsideValidityRange) {
  const Scene scene;
  const TransgraphRenderer& renderer = sceneRenderer();
  const double r = scene.parameters.range.rotation_deg, t = scene.parameters.range.translation_mm;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Eigen::Isometry3d> poses = {scene.T_expected,
                                          scene.poseWithin(Eigen::Vector3d(r, -r, r), Eigen::Vector3d(-t, t, t)),
                                          scene.poseWithin(Eigen::Vector3d(-r, r, -r), Eigen::Vector3d(t, -t, -t))};
  for (int k = 0; k < 3; ++k) {
    poses.push_back(scene.poseWithin(r * Eigen::Vector3d(unit(random), unit(random), unit(random)),
                                     t * Eigen::Vector3d(unit(random), unit(random), unit(random))));
  }
  for (const auto& pose : poses) {
    fct::FloatImage drr;
    fct::DrrRenderStats stats;
    ASSERT_TRUE(renderer.render(scene.view, pose, 0, drr, &stats).ok());
    EXPECT_EQ(stats.fallbackRays, 0u) << "every ray of a pose inside the range is in the table";
    EXPECT_GT(expectInteriorPixelsMatch(scene, scene.view, pose, drr, 0.01), 500);
  }
}

TEST(Transgraph, FallsBackToIntegratorOutsideValidityRange) {
  const Scene scene;
  const TransgraphRenderer& renderer = sceneRenderer();
  const Transgraph& transgraph = renderer.transgraph();
  const Eigen::Isometry3d pose = scene.poseWithin(Eigen::Vector3d(0.0, 35.0, 0.0), Eigen::Vector3d(40.0, 0.0, 0.0));
  fct::FloatImage drr;
  fct::DrrRenderStats stats;
  ASSERT_TRUE(renderer.render(scene.view, pose, 0, drr, &stats).ok());
  const std::size_t fallbacks = stats.fallbackRays;
  EXPECT_GT(fallbacks, 0u);
  std::size_t counted = 0;
  for (int row = 0; row < drr.rows; ++row) {
    for (int col = 0; col < drr.cols; ++col) {
      const auto [source, end] = Scene::pixelRay(scene.view, pose, col, row);
      bool usedFallback = false;
      EXPECT_EQ(transgraph.integrate(source, end, &usedFallback), drr.at(col, row));
      if (usedFallback) {
        ++counted;
        EXPECT_FLOAT_EQ(drr.at(col, row), static_cast<float>(scene.ellipsoid.integral(source, end)));
      }
    }
  }
  EXPECT_EQ(counted, fallbacks);
  expectInteriorPixelsMatch(scene, scene.view, pose, drr, 0.01);
}

TEST(Transgraph, LevelAndPixelListRendersEqualFullRenderPixels) {
  const Scene scene;
  const TransgraphRenderer& renderer = sceneRenderer();
  const Eigen::Isometry3d pose = scene.poseWithin(Eigen::Vector3d(2.0, -3.0, 1.0), Eigen::Vector3d(4.0, 5.0, -6.0));
  for (int level : {1, 2}) {
    fct::FloatImage levelDrr, fullOfLevelCamera;
    ASSERT_TRUE(renderer.render(scene.view, pose, level, levelDrr).ok());
    ASSERT_TRUE(renderer.render(scene.view.downsampled(level), pose, 0, fullOfLevelCamera).ok());
    EXPECT_EQ(levelDrr.cols, 80 >> level);
    EXPECT_EQ(levelDrr.rows, 60 >> level);
    EXPECT_EQ(levelDrr.pixels, fullOfLevelCamera.pixels);

    fct::PixelIndexList pixels;
    for (int i = 0; i < levelDrr.cols * levelDrr.rows; i += 7) pixels.push_back(i);
    std::vector<float> values;
    ASSERT_TRUE(renderer.renderPixels(scene.view, pose, level, pixels, values).ok());
    ASSERT_EQ(values.size(), pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) EXPECT_EQ(values[i], levelDrr.pixels[pixels[i]]);
  }
  // Deterministic: a second render is bit-identical.
  fct::FloatImage first, second;
  ASSERT_TRUE(renderer.render(scene.view, pose, 0, first).ok());
  ASSERT_TRUE(renderer.render(scene.view, pose, 0, second).ok());
  EXPECT_EQ(first.pixels, second.pixels);
}

TEST(Transgraph, RejectsBadInputsWithClearErrors) {
  const Scene scene;
  const auto integrator = scene.ellipsoid.integrator();
  TransgraphParameters zeroSpacing = scene.parameters;
  zeroSpacing.spacing_mm = 0.0;
  auto r1 = Transgraph::build(scene.ct, scene.view, scene.T_expected, zeroSpacing, integrator);
  ASSERT_FALSE(r1.ok());
  EXPECT_NE(r1.error().find("spacing"), std::string::npos) << r1.error();

  auto r2 = Transgraph::build(scene.ct, Camera{}, scene.T_expected, scene.parameters, integrator);
  ASSERT_FALSE(r2.ok());
  EXPECT_NE(r2.error().find("detector size"), std::string::npos) << r2.error();

  auto r3 = Transgraph::build(fct::Volume{}, scene.view, scene.T_expected, scene.parameters, integrator);
  ASSERT_FALSE(r3.ok());
  EXPECT_NE(r3.error().find("empty"), std::string::npos) << r3.error();

  auto r4 = Transgraph::build(scene.ct, scene.view, scene.T_expected, scene.parameters, nullptr);
  ASSERT_FALSE(r4.ok());
  EXPECT_NE(r4.error().find("integrator"), std::string::npos) << r4.error();

  TransgraphParameters tooFine = scene.parameters;
  tooFine.spacing_mm = 0.1;
  auto r5 = Transgraph::plan(scene.ct, scene.view, scene.T_expected, tooFine);
  ASSERT_FALSE(r5.ok());
  EXPECT_NE(r5.error().find("use a spacing of about"), std::string::npos) << r5.error();

  // A source inside the CT: the two-plane table cannot hold its rays.
  const Camera inside = Camera::lookingAt(scene.T_expected * scene.ct.centre_lps_mm(),
                                          scene.view.T_world_from_camera().linear(), 20.0, 500.0, 80, 60, 2.4);
  auto r6 = Transgraph::plan(scene.ct, inside, scene.T_expected, scene.parameters);
  ASSERT_FALSE(r6.ok());
  EXPECT_NE(r6.error().find("source"), std::string::npos) << r6.error();

  auto volume = std::make_shared<const fct::DrrVolume>(fct::DrrVolume::create(scene.ct).value());
  auto r7 = TransgraphRenderer::fromTransgraph(volume, Transgraph{});
  ASSERT_FALSE(r7.ok());
  EXPECT_NE(r7.error().find("empty"), std::string::npos) << r7.error();
  auto r8 = TransgraphRenderer::create(nullptr, scene.view, scene.T_expected, scene.parameters);
  ASSERT_FALSE(r8.ok());
  EXPECT_NE(r8.error().find("empty"), std::string::npos) << r8.error();

  // Rendering through the DrrRenderer interface still checks its inputs.
  const TransgraphRenderer& renderer = sceneRenderer();
  fct::FloatImage drr;
  EXPECT_FALSE(renderer.render(scene.view, scene.T_expected, -1, drr).ok());
  EXPECT_FALSE(renderer.render(Camera{}, scene.T_expected, 0, drr).ok());
  std::vector<float> values{1.0f};
  EXPECT_FALSE(renderer.renderPixels(scene.view, scene.T_expected, 0, {80 * 60}, values).ok());
  ASSERT_TRUE(renderer.renderPixels(scene.view, scene.T_expected, 0, {}, values).ok());
  EXPECT_TRUE(values.empty());
}

TEST(Transgraph, BuildReportsProgressAndHonoursCancel) {
  const Scene scene;
  TransgraphParameters coarse = scene.parameters;
  coarse.spacing_mm = 6.0;
  double lastFraction = -1.0;
  bool monotonic = true;
  fct::ProgressMonitor monitor(
      [&](const fct::ProgressUpdate& u) {
        monotonic = monotonic && u.fraction >= lastFraction;
        lastFraction = u.fraction;
      },
      nullptr);
  auto built = Transgraph::build(scene.ct, scene.view, scene.T_expected, coarse, scene.ellipsoid.integrator(), monitor);
  ASSERT_TRUE(built.ok()) << built.error();
  EXPECT_TRUE(monotonic);
  EXPECT_DOUBLE_EQ(lastFraction, 1.0);

  std::atomic<bool> cancel{true};
  auto cancelled = Transgraph::build(scene.ct, scene.view, scene.T_expected, coarse, scene.ellipsoid.integrator(),
                                     fct::ProgressMonitor({}, &cancel));
  ASSERT_FALSE(cancelled.ok());
  EXPECT_NE(cancelled.error().find("cancelled"), std::string::npos);
}

TEST(TransgraphCache, SecondRunLoadsIdenticalTable) {
  const Scene scene;
  TransgraphParameters coarse = scene.parameters;
  coarse.spacing_mm = 4.0;
  const auto folder = fct::test::scratchDir();
  auto first = TransgraphCache::buildOrLoad(scene.ct, scene.view, scene.T_expected, coarse, scene.ellipsoid.integrator(),
                                       folder);
  ASSERT_TRUE(first.ok()) << first.error();
  EXPECT_FALSE(first.value().buildInfo().loadedFromCache);
  EXPECT_TRUE(first.warnings().empty());
  ASSERT_TRUE(std::filesystem::exists(first.value().buildInfo().cacheFile));
  EXPECT_EQ(first.value().buildInfo().cacheFile.parent_path(), folder);

  auto second = TransgraphCache::buildOrLoad(scene.ct, scene.view, scene.T_expected, coarse, scene.ellipsoid.integrator(),
                                        folder);
  ASSERT_TRUE(second.ok()) << second.error();
  EXPECT_TRUE(second.value().buildInfo().loadedFromCache);
  EXPECT_TRUE(second.warnings().empty());
  EXPECT_EQ(second.value().table(), first.value().table());
  EXPECT_EQ(second.value().layout().counts, first.value().layout().counts);

  // Other CT content gives another key, so it does not reuse the table.
  fct::Volume changed = scene.ct;
  changed.voxels()[99] += 1.0f;
  EXPECT_NE(TransgraphCache::key(changed, scene.view, scene.T_expected, coarse),
            TransgraphCache::key(scene.ct, scene.view, scene.T_expected, coarse));
  TransgraphParameters otherIntegrator = coarse;
  otherIntegrator.integratorId = "other";
  EXPECT_NE(TransgraphCache::key(scene.ct, scene.view, scene.T_expected, otherIntegrator),
            TransgraphCache::key(scene.ct, scene.view, scene.T_expected, coarse));
}

TEST(TransgraphCache, CorruptOrTruncatedFileIsRebuiltWithWarning) {
  const Scene scene;
  TransgraphParameters coarse = scene.parameters;
  coarse.spacing_mm = 4.0;
  const auto folder = fct::test::scratchDir();
  auto original = TransgraphCache::buildOrLoad(scene.ct, scene.view, scene.T_expected, coarse, scene.ellipsoid.integrator(),
                                          folder);
  ASSERT_TRUE(original.ok()) << original.error();
  const auto file = original.value().buildInfo().cacheFile;
  const auto size = std::filesystem::file_size(file);

  const auto damageAndReload = [&](const std::function<void()>& damage, const std::string& expectedReason) {
    damage();
    auto rebuilt = TransgraphCache::buildOrLoad(scene.ct, scene.view, scene.T_expected, coarse,
                                           scene.ellipsoid.integrator(), folder);
    ASSERT_TRUE(rebuilt.ok()) << rebuilt.error();
    EXPECT_FALSE(rebuilt.value().buildInfo().loadedFromCache);
    ASSERT_EQ(rebuilt.warnings().size(), 1u);
    EXPECT_NE(rebuilt.warnings()[0].find(expectedReason), std::string::npos) << rebuilt.warnings()[0];
    EXPECT_EQ(rebuilt.value().table(), original.value().table());
    EXPECT_EQ(std::filesystem::file_size(file), size) << "the rebuilt table was written back";
  };
  const auto flipByteAt = [&](std::uintmax_t offset) {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(offset));
    char c = 0;
    f.get(c);
    f.seekp(static_cast<std::streamoff>(offset));
    f.put(static_cast<char>(c ^ 0x5A));
  };
  damageAndReload([&] { flipByteAt(size / 2); }, "checksum");
  damageAndReload([&] { flipByteAt(0); }, "magic");
  damageAndReload([&] { std::filesystem::resize_file(file, size - 1000); }, "truncated");
  damageAndReload([&] { std::filesystem::resize_file(file, 20); }, "truncated");
}

TEST(TransgraphCache, DefaultFolderFollowsXdgCacheHome) {
  const char* previous = std::getenv("XDG_CACHE_HOME");
  const bool hadXdg = previous != nullptr;
  const std::string saved = hadXdg ? previous : "";
  ::setenv("XDG_CACHE_HOME", "/tmp/fct-xdg-test", 1);
  EXPECT_EQ(TransgraphCache::defaultFolder(), std::filesystem::path("/tmp/fct-xdg-test/fluoroct/transgraph"));
  ::unsetenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  if (home && *home) {
    EXPECT_EQ(TransgraphCache::defaultFolder(), std::filesystem::path(home) / ".cache/fluoroct/transgraph");
  }
  if (hadXdg) ::setenv("XDG_CACHE_HOME", saved.c_str(), 1);
}

}  // namespace
