#pragma once
// A known-truth session for the step widget tests: a small phantom (or any CT) with three simulated 192x192 C-arm
// views (RegistrationTestCase.h), loaded into a StudioDocument with its truth pose, and a shown window holding the
// three X-ray views and the three slice views the steps attach to. Helpers click like a user (QTest) and wait for
// the event loop.

#include <gtest/gtest.h>

#include <QElapsedTimer>
#include <QGridLayout>
#include <QTest>
#include <QWidget>

#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <vector>

#include "Image/BoneSurface.h"
#include "Logic/RegistrationTestCase.h"
#include "Simulation/PhantomBuilder.h"
#include "Widgets/SliceViewWidget.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/XrayViewWidget.h"

namespace fct::test {

/// A document with a simulated case and the views the steps draw on.
struct StepTestSession {
  StudioDocument document;
  Eigen::Isometry3d T_truth = Eigen::Isometry3d::Identity();
  std::unique_ptr<BoneSurface> bone;
  std::unique_ptr<QWidget> window;
  std::vector<XrayViewWidget*> xrayViews;
  std::array<SliceViewWidget*, 3> sliceViews{};

  /// Simulates the case for `ct` and shows the views (fails the test on error).
  explicit StepTestSession(Volume ct) {
    auto simulated = simulateCase(std::move(ct));
    EXPECT_TRUE(simulated.ok()) << simulated.error();
    if (!simulated) return;
    T_truth = simulated.value().T_truth;
    auto ctShared = std::make_shared<const Volume>(std::move(simulated.value().ct));
    bone = std::make_unique<BoneSurface>(BoneSurface::extract(*ctShared).value());
    document.setCt(ctShared);
    document.setViews(simulated.value().views);
    document.setTruthPose(T_truth);

    window = std::make_unique<QWidget>();
    auto* grid = new QGridLayout(window.get());
    for (std::size_t v = 0; v < document.views().size(); ++v) {
      auto* view = new XrayViewWidget(window.get());
      view->setImage(document.views()[v].xray);
      grid->addWidget(view, 0, static_cast<int>(v));
      xrayViews.push_back(view);
    }
    const std::array orientations{SliceOrientation::Axial, SliceOrientation::Coronal, SliceOrientation::Sagittal};
    for (int i = 0; i < 3; ++i) {
      sliceViews[static_cast<std::size_t>(i)] = new SliceViewWidget(orientations[static_cast<std::size_t>(i)], window.get());
      sliceViews[static_cast<std::size_t>(i)]->setVolume(ctShared);
      grid->addWidget(sliceViews[static_cast<std::size_t>(i)], 1, i);
    }
    window->resize(1500, 1000);
    window->show();
    EXPECT_TRUE(QTest::qWaitForWindowExposed(window.get()));
  }

  /// Mean bone-surface distance of a pose from the truth, mm.
  double surfaceError_mm(const Eigen::Isometry3d& T_world_from_ct) const {
    return bone->meanDistance_mm(T_world_from_ct, T_truth);
  }

  /// Up to six bone-surface points far apart, for landmarks: the extremes along LPS x, y and z among the points whose
  /// true projections lie at least 12 px inside every view, each at least 20 mm from the others and projecting at
  /// least 10 px from the others in every view (so a click never lands on an earlier landmark's marker).
  std::vector<Eigen::Vector3d> spreadBonePoints() const {
    const auto& views = document.views();
    const auto uvOf = [&](std::size_t v, const Eigen::Vector3d& p) { return views[v].camera.project(T_truth * p); };
    std::vector<Eigen::Vector3d> visible;
    for (const Eigen::Vector3d& p : bone->points_ct_mm()) {
      bool inside = true;
      for (std::size_t v = 0; v < views.size(); ++v) {
        const Eigen::Vector2d uv = uvOf(v, p);
        inside = inside && uv.x() >= 12 && uv.y() >= 12 && uv.x() <= views[v].xray.cols - 13 &&
                 uv.y() <= views[v].xray.rows - 13;
      }
      if (inside) visible.push_back(p);
    }
    std::vector<Eigen::Vector3d> picked;
    if (visible.empty()) return picked;
    for (int axis = 0; axis < 3; ++axis) {
      for (int sign : {-1, 1}) {
        const Eigen::Vector3d extreme = *std::max_element(visible.begin(), visible.end(), [&](const auto& a, const auto& b) {
          return sign * a[axis] < sign * b[axis];
        });
        const bool apart = std::all_of(picked.begin(), picked.end(), [&](const Eigen::Vector3d& p) {
          if ((p - extreme).norm() <= 20.0) return false;
          for (std::size_t v = 0; v < views.size(); ++v) {
            if ((uvOf(v, p) - uvOf(v, extreme)).norm() < 10.0) return false;
          }
          return true;
        });
        if (apart) picked.push_back(extreme);
      }
    }
    return picked;
  }

  /// Clicks a CT point in the axial view (the slice moved to it first) like a user.
  void clickCt(const Eigen::Vector3d& p_ct_mm) {
    SliceViewWidget* axial = sliceViews[0];
    axial->setCrosshair_ct_mm(p_ct_mm);
    QTest::mouseClick(axial, Qt::LeftButton, Qt::NoModifier, axial->widgetPointForCtPoint(p_ct_mm));
  }

  /// Clicks the true projection of a CT point in X-ray view v.
  void clickTrueProjection(std::size_t v, const Eigen::Vector3d& p_ct_mm) {
    const Eigen::Vector2d uv_px = document.views()[v].camera.project(T_truth * p_ct_mm);
    QTest::mouseClick(xrayViews[v], Qt::LeftButton, Qt::NoModifier, xrayViews[v]->widgetPointForPixel(uv_px));
  }
};

/// Processes events until `done` is true or timeout_ms passes; returns `done()`.
inline bool waitUntil(const std::function<bool()>& done, int timeout_ms) {
  QElapsedTimer timer;
  timer.start();
  while (!done() && timer.elapsed() < timeout_ms) QTest::qWait(10);
  return done();
}

/// Waits (event loop running) until `document`'s case is prepared, starting a background preparation if none runs;
/// false when it fails or takes longer than `timeout_ms`.
inline bool waitForCase(StudioDocument& document, int timeout_ms = 60000) {
  document.prepareCaseInBackground();
  return waitUntil([&] { return document.readyCase() != nullptr || !document.isPreparingCase(); }, timeout_ms) &&
         document.readyCase() != nullptr;
}

}  // namespace fct::test
