// TrackStepWidget: a simulated biplane sequence (the physical simulator, the bone moving) written as TIFF frames with
// a view file, loaded, tracked on the step's worker thread, and scrubbed (each frame with its outline); wrong sequences
// and missing inputs give messages; a cancelled run keeps its frames and leaves no thread.
#include <gtest/gtest.h>

#include <QTest>

#include <fmt/format.h>

#include "IO/Project/ViewFile.h"
#include "IO/Xray/ImageFileWriter.h"
#include "Logic/TrackingTestSequence.h"
#include "StepTestSession.h"
#include "TestSupport.h"
#include "Widgets/TrackStepWidget.h"

namespace {

/// The open case's views replaced by a simulated biplane sequence's (frame 0), started at frame 0's true pose.
struct TrackSession {
  fct::test::StepTestSession session{fct::test::smallPhantom()};
  fct::test::SimulatedSequence sequence;
  std::filesystem::path folder = fct::test::workDir();

  /// `fine`: 192 px of 1.6 mm, as the registration tests' cases, for tests of accuracy (on 128 px of 2.4 mm a start at
  /// the truth of frame 0 already ended 0.6-1.5 mm away, and which of those depended on rounding in the sixth digit
  /// of the DRR); otherwise 128 px of 2.4 mm.
  explicit TrackSession(int frames, bool fine = false) {
    fct::test::SequenceOptions options;
    options.viewCount = 2;
    options.frames = frames;
    if (fine) {
      options.size_px = 192;
      options.pixelSpacing_mm = 1.6;
    }
    auto simulated = fct::test::simulateSequence(*session.document.ct(), options);
    EXPECT_TRUE(simulated.ok()) << simulated.error();
    if (!simulated) return;
    sequence = std::move(simulated).value();
    session.document.setViews(sequence.views);
    session.document.setInitialPose(sequence.T_truth.front(), "truth of frame 0");
  }

  /// Writes every frame as TIFF and a view file giving each view its frames (names of the views: `names`, or the
  /// sequence's); returns the view file.
  std::filesystem::path writeViewFile(std::vector<std::string> names = {}) const {
    std::vector<fct::ViewSpec> specs;
    for (std::size_t v = 0; v < sequence.views.size(); ++v) {
      fct::ViewSpec spec;
      spec.name = names.empty() ? sequence.views[v].name : names[v];
      spec.camera = sequence.views[v].camera;
      fct::ViewSequence frames;
      for (std::size_t f = 0; f < sequence.frames.size(); ++f) {
        const fct::XrayImage& image = sequence.frames[f][v];
        const std::filesystem::path path = folder / fmt::format("{}_{:03}.tif", spec.name, f);
        EXPECT_TRUE(fct::ImageFileWriter::writeTiff({image.cols, image.rows, image.pixels}, path).ok());
        frames.files.push_back(path);
      }
      spec.imagePath = frames.files.front();
      spec.sequence = frames;
      specs.push_back(spec);
    }
    const std::filesystem::path viewFile = folder / "sequence.json";
    EXPECT_TRUE(fct::ViewFile::write(specs, viewFile).ok());
    return viewFile;
  }

  std::vector<fct::XrayViewWidget*> views() const { return {session.xrayViews[0], session.xrayViews[1]}; }
};

bool waitUntilIdle(const fct::TrackStepWidget& step) {
  return QTest::qWaitFor([&] { return !step.isRunning(); }, 300000);
}

}  // namespace

TEST(TrackStepWidget, TracksALoadedSequenceAndShowsEveryFrameWithItsOutline) {
  TrackSession t(4, true);
  ASSERT_EQ(t.sequence.frames.size(), 4u);
  fct::TrackStepWidget step(&t.session.document);
  step.attachViews(t.views(), t.session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(step.loadSequence(t.writeViewFile()).ok()) << step.message().toStdString();
  EXPECT_EQ(step.frameCount(), 4);

  step.startTracking();
  EXPECT_TRUE(step.isRunning());
  ASSERT_TRUE(waitUntilIdle(step));
  ASSERT_EQ(step.trackedFrames().size(), 4u) << step.message().toStdString();
  EXPECT_TRUE(step.message().startsWith("Tracked 4 of 4 frames")) << step.message().toStdString();
  const fct::BoneSurface bone = fct::BoneSurface::extract(*t.session.document.ct()).value();
  for (const fct::TrackedFrame& frame : step.trackedFrames()) {
    EXPECT_EQ(frame.status, fct::TrackedFrameStatus::Tracked) << "frame " << frame.index;
    EXPECT_LT(bone.meanDistance_mm(frame.T_world_from_ct, t.sequence.T_truth[static_cast<std::size_t>(frame.index)]), 1.0)
        << "frame " << frame.index;
  }
  EXPECT_FALSE(step.poseChart().isNull());

  step.showFrame(2);
  EXPECT_EQ(step.shownFrame(), 2);
  for (std::size_t v = 0; v < 2; ++v) {
    EXPECT_EQ(t.views()[v]->image().pixels, t.sequence.frames[2][v].pixels) << "view " << v << " shows frame 2";
    EXPECT_TRUE(t.views()[v]->isLayerVisible(fct::TrackStepWidget::kTrackLayer));
  }
  step.setActive(false);
  for (std::size_t v = 0; v < 2; ++v) {
    EXPECT_FALSE(t.views()[v]->hasLayer(fct::TrackStepWidget::kTrackLayer));
    EXPECT_EQ(t.views()[v]->image().pixels, t.session.document.views()[v].xray.pixels) << "the case's X-ray is back";
  }
}

TEST(TrackStepWidget, RefusesMissingInputsAndASequenceOfOtherViews) {
  TrackSession t(2);
  fct::TrackStepWidget step(&t.session.document);
  step.attachViews(t.views(), t.session.sliceViews);
  step.setActive(true);
  step.startTracking();
  EXPECT_FALSE(step.isRunning());
  EXPECT_TRUE(step.message().contains("No sequence loaded")) << step.message().toStdString();

  const auto otherViews = step.loadSequence(t.writeViewFile({"left", "right"}));
  ASSERT_FALSE(otherViews.ok());
  EXPECT_NE(otherViews.error().find("not a sequence of the open case's C-arm views"), std::string::npos)
      << otherViews.error();
  EXPECT_EQ(step.frameCount(), 0);

  std::vector<fct::ViewSpec> still;
  for (const fct::RegistrationView& view : t.sequence.views) {
    fct::ViewSpec spec;
    spec.name = view.name;
    spec.camera = view.camera;
    still.push_back(spec);
  }
  ASSERT_TRUE(fct::ViewFile::write(still, t.folder / "still.json").ok());
  const auto noSequence = step.loadSequence(t.folder / "still.json");
  ASSERT_FALSE(noSequence.ok());
  EXPECT_NE(noSequence.error().find("has no \"sequence\""), std::string::npos) << noSequence.error();

  ASSERT_TRUE(step.loadSequence(t.writeViewFile()).ok()) << step.message().toStdString();
  t.session.document.setInitialPose(std::nullopt);
  step.startTracking();
  EXPECT_FALSE(step.isRunning());
  EXPECT_TRUE(step.message().contains("No start pose")) << step.message().toStdString();
}

TEST(TrackStepWidget, CancelKeepsTheFramesDoneAndLeavesNoThread) {
  // Enough frames that the run cannot end before the Cancel, pressed when frame 0 shows, reaches the worker (a later
  // frame takes a few milliseconds here).
  TrackSession t(30);
  fct::TrackStepWidget step(&t.session.document);
  step.attachViews(t.views(), t.session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(step.loadSequence(t.writeViewFile()).ok()) << step.message().toStdString();
  QObject::connect(&step, &fct::TrackStepWidget::frameDone, &step, [&step](int index) {
    if (index == 0) step.cancel();  // as a user pressing Cancel once frame 0 shows
  });
  step.startTracking();
  ASSERT_TRUE(waitUntilIdle(step));
  ASSERT_FALSE(step.trackedFrames().empty());
  EXPECT_LT(step.trackedFrames().size(), 30u);
  EXPECT_TRUE(step.message().startsWith("Cancelled after")) << step.message().toStdString();
  for (std::size_t i = 0; i < step.trackedFrames().size(); ++i) {
    EXPECT_EQ(step.trackedFrames()[i].index, static_cast<int>(i));
  }
}
