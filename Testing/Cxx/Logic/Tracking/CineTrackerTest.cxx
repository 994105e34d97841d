// CineTracker: follows a short simulated sequence (physical simulator, moving phantom bone) frame by frame, flags a
// dropout frame and recovers after it, keeps frames whose re-registration confirms the pose;
// RegistrationCase::replaceXray (the frame swap); bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "Registration/RegistrationCase.h"
#include "RegistrationTestCase.h"
#include "Tracking/CineTracker.h"
#include "TrackingTestSequence.h"

namespace {

/// A biplane 128^2 sequence of the phantom and a case prepared on its frame 0.
struct Tracked {
  fct::Volume ct;
  fct::test::SimulatedSequence sequence;
  fct::RegistrationCase registrationCase;
};

Tracked prepare(int frames, int viewCount = 2, int size_px = 128, double pixelSpacing_mm = 2.4) {
  fct::Volume ct = fct::test::smallPhantom();
  fct::test::SequenceOptions options;
  options.frames = frames;
  options.viewCount = viewCount;
  options.size_px = size_px;
  options.pixelSpacing_mm = pixelSpacing_mm;
  auto sequence = fct::test::simulateSequence(ct, options);
  EXPECT_TRUE(sequence.ok()) << sequence.error();
  fct::RegistrationCaseOptions caseOptions;
  caseOptions.cutFaceMargin_mm = -1.0;  // the frames are DRRs of this CT alone: no anatomy beyond its end faces
  auto registrationCase = fct::RegistrationCase::create(ct, sequence.value().views, caseOptions);
  EXPECT_TRUE(registrationCase.ok()) << registrationCase.error();
  return Tracked{std::move(ct), std::move(sequence).value(), std::move(registrationCase).value()};
}

fct::CineTrackerOptions fastTracker() {
  fct::CineTrackerOptions options;
  options.firstFrame.schedule = fct::RegistrationSchedule::builtin("fast").value();
  options.level = 0;  // the 128^2 test detector: its 1:4 level has 4.8 mm pixels
  return options;
}

double errorOf(const Tracked& t, const fct::TrackedFrame& frame) {
  return t.registrationCase.bone()->meanDistance_mm(frame.T_world_from_ct, t.sequence.T_truth[frame.index]);
}

/// Frame 0 starts 3 mm (mean surface distance) off the truth.
Eigen::Isometry3d firstStart(const Tracked& t) {
  Eigen::Isometry3d T = t.sequence.T_truth[0];
  T.translation() += Eigen::Vector3d(2.0, -1.5, 1.5);
  return T;
}

/// Blends every pixel away from the border with the mean of its 3x3 neighbourhood: (1 - a) x pixel + a x mean.
void soften(fct::XrayImage& image, double a) {
  std::vector<float> out = image.pixels;
  for (int row = 1; row + 1 < image.rows; ++row) {
    for (int col = 1; col + 1 < image.cols; ++col) {
      double sum = 0.0;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -1; dc <= 1; ++dc) sum += image.at(col + dc, row + dr);
      }
      out[static_cast<std::size_t>(row) * image.cols + col] = static_cast<float>((1.0 - a) * image.at(col, row) +
                                                                                 a * sum / 9.0);
    }
  }
  image.pixels = std::move(out);
}

}  // namespace

TEST(CineTracker, FollowsSmoothlyMovingBoneWithinAMillimetrePerFrame) {
  Tracked t = prepare(6);
  auto tracker = fct::CineTracker::create(t.registrationCase, fastTracker());
  ASSERT_TRUE(tracker.ok()) << tracker.error();
  auto first = tracker.value().trackFirst(firstStart(t));
  ASSERT_TRUE(first.ok()) << first.error();
  EXPECT_LT(errorOf(t, first.value()), 1.0);  // the fast preset on a 128^2 biplane case
  for (std::size_t f = 1; f < t.sequence.frames.size(); ++f) {
    auto frame = tracker.value().trackNext(t.sequence.frames[f]);
    ASSERT_TRUE(frame.ok()) << frame.error();
    EXPECT_EQ(frame.value().index, static_cast<int>(f));
    EXPECT_EQ(frame.value().status, fct::TrackedFrameStatus::Tracked) << "frame " << f;
    EXPECT_LT(errorOf(t, frame.value()), 1.0) << "frame " << f;
    EXPECT_GT(frame.value().drrs, 0);
    EXPECT_FALSE(frame.value().cancelled);
    std::printf("frame %zu: error %.3f mm, similarity %.4f, %ld DRRs\n", f, errorOf(t, frame.value()),
                frame.value().similarity, frame.value().drrs);
  }
}

TEST(CineTracker, ShuffledFrameIsFlaggedAndTheNextFramesTrackAgain) {
  Tracked t = prepare(6);
  auto tracker = fct::CineTracker::create(t.registrationCase, fastTracker());
  ASSERT_TRUE(tracker.ok()) << tracker.error();
  ASSERT_TRUE(tracker.value().trackFirst(firstStart(t)).ok());
  std::mt19937 random(3);
  for (std::size_t f = 1; f < t.sequence.frames.size(); ++f) {
    std::vector<fct::XrayImage> images = t.sequence.frames[f];
    if (f == 3) {
      for (fct::XrayImage& image : images) std::shuffle(image.pixels.begin(), image.pixels.end(), random);
    }
    auto frame = tracker.value().trackNext(images);
    ASSERT_TRUE(frame.ok()) << frame.error();
    if (f == 3) {
      EXPECT_EQ(frame.value().status, fct::TrackedFrameStatus::Lost);
    } else {
      EXPECT_NE(frame.value().status, fct::TrackedFrameStatus::Lost) << "frame " << f;
      EXPECT_LT(errorOf(t, frame.value()), 1.0) << "frame " << f;
    }
  }
}

TEST(CineTracker, CancelledFrameIsMarked) {
  Tracked t = prepare(2, 1);
  auto tracker = fct::CineTracker::create(t.registrationCase, fastTracker());
  ASSERT_TRUE(tracker.ok()) << tracker.error();
  ASSERT_TRUE(tracker.value().trackFirst(firstStart(t)).ok());
  const std::atomic<bool> cancel{true};
  auto frame = tracker.value().trackNext(t.sequence.frames[1], &cancel);
  ASSERT_TRUE(frame.ok()) << frame.error();
  EXPECT_TRUE(frame.value().cancelled);
}

TEST(CineTracker, RejectsBadOptionsAndFrames) {
  Tracked t = prepare(2, 1);
  fct::CineTrackerOptions options = fastTracker();
  options.level = 7;
  auto badLevel = fct::CineTracker::create(t.registrationCase, options);
  ASSERT_FALSE(badLevel.ok());
  EXPECT_NE(badLevel.error().find("level 7"), std::string::npos) << badLevel.error();
  options = fastTracker();
  options.dissimilarityGrowth = 1.0;
  EXPECT_FALSE(fct::CineTracker::create(t.registrationCase, options).ok());
  for (const double badScale : {0.5, 101.0, std::nan("")}) {
    options = fastTracker();
    options.depthScale = badScale;
    auto rejected = fct::CineTracker::create(t.registrationCase, options);
    ASSERT_FALSE(rejected.ok()) << badScale;
    EXPECT_NE(rejected.error().find("depth scale"), std::string::npos) << rejected.error();
  }
  options = fastTracker();
  options.confirmTolerance_deg = 0.0;
  auto confirmTolerance = fct::CineTracker::create(t.registrationCase, options);
  ASSERT_FALSE(confirmTolerance.ok());
  EXPECT_NE(confirmTolerance.error().find("confirmation tolerances"), std::string::npos) << confirmTolerance.error();
  options = fastTracker();
  options.frameDrr = fct::DrrMethod::Transgraph;
  auto tableFrames = fct::CineTracker::create(t.registrationCase, options);
  ASSERT_FALSE(tableFrames.ok());
  EXPECT_NE(tableFrames.error().find("raycast or siddon"), std::string::npos) << tableFrames.error();

  auto tracker = fct::CineTracker::create(t.registrationCase, fastTracker());
  ASSERT_TRUE(tracker.ok()) << tracker.error();
  auto early = tracker.value().trackNext(t.sequence.frames[1]);
  ASSERT_FALSE(early.ok());
  EXPECT_NE(early.error().find("trackFirst"), std::string::npos) << early.error();
  ASSERT_TRUE(tracker.value().trackFirst(firstStart(t)).ok());
  auto twoImages = tracker.value().trackNext({t.sequence.frames[1][0], t.sequence.frames[1][0]});
  ASSERT_FALSE(twoImages.ok());
  EXPECT_NE(twoImages.error().find("2 images given for 1 views"), std::string::npos) << twoImages.error();
}

TEST(CineTracker, AutomaticLevelIsTheFinestAtMost160PixelsAcross) {
  fct::CineTrackerOptions options;
  options.firstFrame.schedule = fct::RegistrationSchedule::builtin("fast").value();
  ASSERT_EQ(options.level, fct::CineTrackerOptions::kAutomaticLevel);
  Tracked small = prepare(1, 1);  // 128^2: levels of 128, 64 and 32 px
  auto atSmall = fct::CineTracker::create(small.registrationCase, options);
  ASSERT_TRUE(atSmall.ok()) << atSmall.error();
  EXPECT_EQ(atSmall.value().options().level, 0);
  EXPECT_EQ(atSmall.value().frameSchedule().stages.front().level, 0);
  Tracked large = prepare(1, 1, 384, 0.8);  // levels of 384, 192 and 96 px
  auto atLarge = fct::CineTracker::create(large.registrationCase, options);
  ASSERT_TRUE(atLarge.ok()) << atLarge.error();
  EXPECT_EQ(atLarge.value().options().level, 2);
  options.level = -2;
  EXPECT_FALSE(fct::CineTracker::create(large.registrationCase, options).ok());
}

TEST(RegistrationCase, ReplaceXrayPreparesTheNewFrameAndKeepsTheViewOnBadInput) {
  Tracked t = prepare(2, 1);
  fct::RegistrationCase& c = t.registrationCase;
  const std::vector<float> frame0 = c.prepared(0).pyramid.level(1).image.pixels;
  ASSERT_TRUE(c.rois(0, 1, 7, 0.1).ok());

  ASSERT_TRUE(c.replaceXray(0, t.sequence.frames[1][0]).ok());
  const std::vector<float> frame1 = c.prepared(0).pyramid.level(1).image.pixels;
  EXPECT_NE(frame0, frame1);
  ASSERT_TRUE(c.rois(0, 1, 7, 0.1).ok());  // statistics recomputed on the new frame

  fct::XrayImage small = t.sequence.frames[1][0];
  small.cols = small.rows = 64;
  small.pixels.resize(64 * 64);
  auto wrongSize = c.replaceXray(0, small);
  ASSERT_FALSE(wrongSize.ok());
  EXPECT_NE(wrongSize.error().find("64x64"), std::string::npos) << wrongSize.error();
  fct::XrayImage blank = t.sequence.frames[1][0];
  std::fill(blank.pixels.begin(), blank.pixels.end(), 1000.0f);
  auto constant = c.replaceXray(0, blank);
  ASSERT_FALSE(constant.ok());
  EXPECT_NE(constant.error().find("blank"), std::string::npos) << constant.error();
  EXPECT_FALSE(c.replaceXray(5, t.sequence.frames[1][0]).ok());
  EXPECT_EQ(c.prepared(0).pyramid.level(1).image.pixels, frame1);
}

TEST(CineTracker, OneViewFramesRenderTrilinearDrrsWithTheDepthScaleAndTwoViewsBoxVoxels) {
  Tracked t = prepare(1, 1);  // a Siddon case: the frame stage renders exactly, with the frame DRR method
  auto tracker = fct::CineTracker::create(t.registrationCase, fastTracker());
  ASSERT_TRUE(tracker.ok()) << tracker.error();
  const fct::RegistrationStage& stage = tracker.value().frameSchedule().stages.front();
  EXPECT_TRUE(stage.exactDrr);
  ASSERT_TRUE(stage.drrMethod.has_value());
  EXPECT_EQ(*stage.drrMethod, fct::DrrMethod::RayCast);
  EXPECT_EQ(tracker.value().options().frameDrr, fct::DrrMethod::RayCast) << "the automatic choice, resolved";
  EXPECT_EQ(stage.drrStep_voxels, fct::CineTrackerOptions::kFrameRayCastStep_voxels);
  EXPECT_EQ(stage.depthScale, fct::CineTrackerOptions{}.depthScale);
  Tracked biplane = prepare(1, 2);
  auto twoViews = fct::CineTracker::create(biplane.registrationCase, fastTracker());
  ASSERT_TRUE(twoViews.ok()) << twoViews.error();
  EXPECT_EQ(twoViews.value().frameSchedule().stages.front().drrMethod, fct::DrrMethod::Siddon);
  EXPECT_EQ(twoViews.value().frameSchedule().stages.front().drrStep_voxels, 0.0);
  fct::CineTrackerOptions boxVoxels = fastTracker();
  boxVoxels.frameDrr = fct::DrrMethod::Siddon;
  boxVoxels.depthScale = 1.0;
  auto siddon = fct::CineTracker::create(t.registrationCase, boxVoxels);
  ASSERT_TRUE(siddon.ok()) << siddon.error();
  EXPECT_EQ(*siddon.value().frameSchedule().stages.front().drrMethod, fct::DrrMethod::Siddon);
  EXPECT_EQ(siddon.value().frameSchedule().stages.front().drrStep_voxels, 0.0);
  EXPECT_EQ(siddon.value().frameSchedule().stages.front().depthScale, 1.0);
}

TEST(CineTracker, ExactRefinementFollowsTheFrameStage) {
  Tracked t = prepare(3);
  fct::CineTrackerOptions options = fastTracker();
  options.refineEvaluations = 15;
  auto tracker = fct::CineTracker::create(t.registrationCase, options);
  ASSERT_TRUE(tracker.ok()) << tracker.error();
  ASSERT_EQ(tracker.value().frameSchedule().stages.size(), 2u);
  EXPECT_TRUE(tracker.value().frameSchedule().stages.back().exactDrr);
  EXPECT_EQ(tracker.value().frameSchedule().stages.back().drrMethod, fct::DrrMethod::Siddon) << "two views";
  EXPECT_EQ(tracker.value().frameSchedule().stages.back().maxEvaluations, 15);
  ASSERT_TRUE(tracker.value().trackFirst(firstStart(t)).ok());
  for (std::size_t f = 1; f < t.sequence.frames.size(); ++f) {
    auto frame = tracker.value().trackNext(t.sequence.frames[f]);
    ASSERT_TRUE(frame.ok()) << frame.error();
    EXPECT_EQ(frame.value().status, fct::TrackedFrameStatus::Tracked) << "frame " << f;
    EXPECT_LT(errorOf(t, frame.value()), 1.0) << "frame " << f;
  }
  options.refineEvaluations = -1;
  EXPECT_FALSE(fct::CineTracker::create(t.registrationCase, options).ok());
}

TEST(CineTracker, SinglePlanePredictionCarriesOnlyPartOfTheMotionAlongTheViewingRay) {
  for (const int viewCount : {1, 2}) {
    Tracked t = prepare(4, viewCount);
    fct::CineTrackerOptions options = fastTracker();
    options.depthVelocityFactor = 0.25;
    auto tracker = fct::CineTracker::create(t.registrationCase, options);
    ASSERT_TRUE(tracker.ok()) << tracker.error();
    auto first = tracker.value().trackFirst(firstStart(t));
    ASSERT_TRUE(first.ok()) << first.error();
    const Eigen::Vector3d& c_ct_mm = t.registrationCase.rotationCentre_ct_mm();
    const Eigen::Vector3d source_world_mm = t.registrationCase.camera(0).sourcePosition_world_mm();
    std::vector<Eigen::Isometry3d> tracked = {first.value().T_world_from_ct};
    for (std::size_t f = 1; f < t.sequence.frames.size(); ++f) {
      auto frame = tracker.value().trackNext(t.sequence.frames[f]);
      ASSERT_TRUE(frame.ok()) << frame.error();
      ASSERT_EQ(frame.value().status, fct::TrackedFrameStatus::Tracked) << "frame " << f;
      if (f >= 2) {
        const Eigen::Vector3d c1 = tracked[f - 1] * c_ct_mm, c0 = tracked[f - 2] * c_ct_mm;
        const Eigen::Vector3d ray = (c1 - source_world_mm).normalized();
        const Eigen::Vector3d lastMove = c1 - c0;
        const Eigen::Vector3d predictedMove = frame.value().T_predicted_world_from_ct * c_ct_mm - c1;
        const double alongFactor = viewCount == 1 ? 0.25 : 1.0;  // biplane sees the depth: full velocity
        EXPECT_NEAR(predictedMove.dot(ray), alongFactor * lastMove.dot(ray), 1e-6) << viewCount << " views, frame " << f;
        EXPECT_LT((predictedMove - predictedMove.dot(ray) * ray - (lastMove - lastMove.dot(ray) * ray)).norm(), 1e-6)
            << viewCount << " views, frame " << f;
        const Eigen::Vector3d trueMove = t.sequence.T_truth[f - 1] * c_ct_mm - t.sequence.T_truth[f - 2] * c_ct_mm;
        EXPECT_GT(std::abs(trueMove.dot(ray)), 0.01) << "the sequence should move along the ray for this test";
      }
      tracked.push_back(frame.value().T_world_from_ct);
    }
  }
  Tracked t = prepare(1, 1);
  fct::CineTrackerOptions options = fastTracker();
  for (const double bad : {-0.1, 1.5, std::nan("")}) {
    options.depthVelocityFactor = bad;
    auto rejected = fct::CineTracker::create(t.registrationCase, options);
    ASSERT_FALSE(rejected.ok()) << bad;
    EXPECT_NE(rejected.error().find("depth velocity"), std::string::npos) << rejected.error();
  }
}

TEST(CineTracker, ReRegistrationThatConfirmsThePoseKeepsAFrameWhoseImageSpoilsTheMatch) {
  // Every frame softer than the last (a = 0.2 per frame, as motion blur or a growing overlay would): the similarity
  // falls from about 0.99 to 0.98 while the pose stays right, until a frame exceeds 1.75x the reference dissimilarity.
  Tracked t = prepare(8);
  for (std::size_t f = 1; f < t.sequence.frames.size(); ++f) {
    for (fct::XrayImage& image : t.sequence.frames[f]) soften(image, std::min(1.0, 0.2 * static_cast<double>(f)));
  }
  const auto track = [&t](const fct::CineTrackerOptions& options) {
    auto tracker = fct::CineTracker::create(t.registrationCase, options);
    EXPECT_TRUE(tracker.ok()) << tracker.error();
    std::vector<fct::TrackedFrame> frames;
    for (std::size_t v = 0; v < t.sequence.views.size(); ++v) {  // trackFirst registers the case's current images
      EXPECT_TRUE(t.registrationCase.replaceXray(v, t.sequence.frames[0][v]).ok());
    }
    if (!tracker.ok() || !tracker.value().trackFirst(firstStart(t)).ok()) return frames;
    for (std::size_t f = 1; f < t.sequence.frames.size(); ++f) {
      auto frame = tracker.value().trackNext(t.sequence.frames[f]);
      EXPECT_TRUE(frame.ok()) << frame.error();
      if (!frame.ok()) break;
      std::printf("frame %zu: %s, similarity %.4f, error %.3f mm %s\n", f,
                  fct::CineTracker::statusName(frame.value().status), frame.value().similarity,
                  errorOf(t, frame.value()), frame.value().note.c_str());
      frames.push_back(frame.value());
    }
    return frames;
  };
  const auto count = [](const std::vector<fct::TrackedFrame>& frames, fct::TrackedFrameStatus status) {
    return std::count_if(frames.begin(), frames.end(),
                         [status](const fct::TrackedFrame& f) { return f.status == status; });
  };

  const std::vector<fct::TrackedFrame> confirmed = track(fastTracker());
  ASSERT_EQ(confirmed.size(), t.sequence.frames.size() - 1);
  EXPECT_EQ(count(confirmed, fct::TrackedFrameStatus::Lost), 0);
  EXPECT_GE(count(confirmed, fct::TrackedFrameStatus::Recovered), 1);
  for (const fct::TrackedFrame& frame : confirmed) {
    EXPECT_LT(errorOf(t, frame), 1.5) << "frame " << frame.index;  // the softened frames cost accuracy: 1.0 mm seen
    if (frame.status == fct::TrackedFrameStatus::Recovered) {
      EXPECT_NE(frame.note.find("confirmed the tracked pose"), std::string::npos) << frame.note;
    }
  }

  // The same frames when the two searches must agree within 0.01 mm: the suspect frame is lost.
  fct::CineTrackerOptions strict = fastTracker();
  strict.confirmTolerance_mm = 0.01;
  EXPECT_GE(count(track(strict), fct::TrackedFrameStatus::Lost), 1);
}
