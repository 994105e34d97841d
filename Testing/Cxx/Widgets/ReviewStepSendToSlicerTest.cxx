// ReviewStepWidget "Send to Slicer": a click sends the final pose to a loopback OpenIGTLink server (IgtlTestReceiver,
// standing in for 3D Slicer's OpenIGTLinkIF) as the TRANSFORM 'FluoroCT' in RAS; a refused port and a missing result
// are shown in the message line.
#include <gtest/gtest.h>

#include <QPushButton>
#include <QSignalSpy>
#include <QTest>

#include "IgtlTestReceiver.h"
#include "Interop/IgtlTransformSender.h"
#include "StepTestSession.h"
#include "Widgets/ReviewStepWidget.h"

namespace {

/// A result whose final pose has no symmetry the LPS -> RAS flip could hide.
fct::RegistrationResult tiltedResult(const Eigen::Isometry3d& T_initial) {
  fct::RegistrationResult result;
  result.T_initial = T_initial;
  result.T_world_from_ct = T_initial;
  result.T_world_from_ct.rotate(Eigen::AngleAxisd(0.1, Eigen::Vector3d(3.0, -1.0, 2.0).normalized()));
  result.T_world_from_ct.pretranslate(Eigen::Vector3d(4.0, -7.5, 2.25));
  return result;
}

/// Clicks "Send to Slicer" and waits for the send to finish; returns whether it was sent.
bool clickSendAndWait(fct::ReviewStepWidget& step) {
  QSignalSpy finished(&step, &fct::ReviewStepWidget::slicerSendFinished);
  auto* button = step.findChild<QPushButton*>(QStringLiteral("sendToSlicerButton"));
  EXPECT_NE(button, nullptr);
  if (!button) return false;
  QTest::mouseClick(button, Qt::LeftButton);
  if (finished.isEmpty() && !finished.wait(10000)) return false;
  return finished.first().first().toBool();
}

}  // namespace

TEST(ReviewStepWidget, SendToSlicerDeliversTheFinalPoseInRas) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  const fct::RegistrationResult result = tiltedResult(session.T_truth);
  session.document.addResult(result);
  fct::ReviewStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document)) << "the DRR's case, prepared in the background";
  fct::test::IgtlTestReceiver receiver(fct::test::IgtlTestReceiver::Behaviour::Record, 1);
  ASSERT_GT(receiver.port(), 0);
  step.setSlicerAddress(QStringLiteral("127.0.0.1"), receiver.port());
  ASSERT_TRUE(clickSendAndWait(step)) << step.message().toStdString();
  EXPECT_NE(step.message().indexOf(QStringLiteral("Sent the final pose to 3D Slicer")), -1) << step.message().toStdString();
  const std::vector<fct::test::ReceivedTransform> received = receiver.received();
  fct::test::IgtlTestReceiver::print(received);
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].deviceName, "FluoroCT");
  EXPECT_TRUE(received[0].matrix.isApprox(fct::IgtlTransformSender::rasFromLps(result.T_world_from_ct), 1e-5))
      << received[0].matrix;
}

TEST(ReviewStepWidget, SendToSlicerShowsARefusedConnectionAndAMissingResult) {
  fct::test::StepTestSession session(fct::test::smallPhantom());
  fct::ReviewStepWidget step(&session.document);
  step.attachViews(session.xrayViews, session.sliceViews);
  step.setActive(true);
  ASSERT_TRUE(fct::test::waitForCase(session.document)) << "the DRR's case, prepared in the background";
  const int port = fct::test::IgtlTestReceiver::unusedPort();
  ASSERT_GT(port, 0);
  step.setSlicerAddress(QStringLiteral("127.0.0.1"), port);
  EXPECT_FALSE(clickSendAndWait(step));
  EXPECT_NE(step.message().indexOf(QStringLiteral("No registration result to send")), -1) << step.message().toStdString();

  session.document.addResult(tiltedResult(session.T_truth));
  EXPECT_FALSE(clickSendAndWait(step));
  EXPECT_NE(step.message().indexOf(QStringLiteral("Not sent to 3D Slicer")), -1) << step.message().toStdString();
  EXPECT_NE(step.message().indexOf(QStringLiteral("connection refused")), -1) << step.message().toStdString();
}
