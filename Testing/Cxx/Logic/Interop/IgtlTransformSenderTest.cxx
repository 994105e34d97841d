// IgtlTransformSender against a loopback OpenIGTLink server (IgtlTestReceiver): the TRANSFORM arrives with the device
// name and the pose in Slicer's RAS frame; refused, closed and bad inputs fail with a message.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <sys/socket.h>
#include <netinet/in.h>
#include <unistd.h>

#include "IgtlTestReceiver.h"
#include "Interop/IgtlTransformSender.h"

namespace fct {
namespace {

using test::IgtlTestReceiver;

/// A pose with no symmetry the LPS -> RAS flip could hide: rotation about a tilted axis, translation on all axes.
Eigen::Isometry3d nonSymmetricPose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(12.5, -30.25, 47.0);
  return T;
}

TEST(IgtlTransformSender, RasFromLpsFlipsTheFirstTwoAxesOnBothSides) {
  const Eigen::Isometry3d T = nonSymmetricPose();
  const Eigen::Matrix4d ras = IgtlTransformSender::rasFromLps(T);
  const Eigen::Matrix4d& lps = T.matrix();
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) {
      const double sign = ((row < 2) != (col < 2)) ? -1.0 : 1.0;
      EXPECT_DOUBLE_EQ(ras(row, col), sign * lps(row, col)) << row << "," << col;
    }
  }
  // A point mapped in RAS equals the LPS mapping, flipped.
  const Eigen::Vector3d p_ct_lps(3.0, -7.0, 11.0);
  const Eigen::Vector3d flip(-1.0, -1.0, 1.0);
  const Eigen::Vector4d p_world_ras = ras * (flip.cwiseProduct(p_ct_lps)).homogeneous();
  EXPECT_TRUE(p_world_ras.head<3>().isApprox(flip.cwiseProduct(T * p_ct_lps), 1e-12));
}

TEST(IgtlTransformSender, LoopbackServerReceivesTheDeviceNameAndTheRasMatrix) {
  IgtlTestReceiver receiver(IgtlTestReceiver::Behaviour::Record, 2);
  ASSERT_GT(receiver.port(), 0);
  IgtlTransformSender sender({"127.0.0.1", receiver.port()}, "BoneFromFluoroCT");
  const Eigen::Isometry3d T = nonSymmetricPose();
  ASSERT_TRUE(sender.send(Eigen::Isometry3d::Identity()).ok());
  const Status sent = sender.send(T);
  ASSERT_TRUE(sent.ok()) << sent.error();
  sender.close();
  const std::vector<test::ReceivedTransform> received = receiver.received();
  IgtlTestReceiver::print(received);
  ASSERT_EQ(received.size(), 2u);
  EXPECT_EQ(received[0].deviceName, "BoneFromFluoroCT");
  EXPECT_TRUE(received[0].matrix.isApprox(Eigen::Matrix4d::Identity(), 1e-6));
  EXPECT_TRUE(received[1].matrix.isApprox(IgtlTransformSender::rasFromLps(T), 1e-5)) << received[1].matrix;
  EXPECT_FALSE(received[1].matrix.isApprox(T.matrix(), 1e-3));  // the RAS flip was applied
}

TEST(IgtlTransformSender, RefusedConnectionSaysNothingListensAndHowToStartSlicersServer) {
  const int port = IgtlTestReceiver::unusedPort();
  IgtlTransformSender sender({"127.0.0.1", port}, "FluoroCT");
  const Status sent = sender.send(nonSymmetricPose());
  ASSERT_FALSE(sent.ok());
  EXPECT_NE(sent.error().find("127.0.0.1:" + std::to_string(port)), std::string::npos) << sent.error();
  EXPECT_NE(sent.error().find("connection refused"), std::string::npos) << sent.error();
  EXPECT_NE(sent.error().find("OpenIGTLinkIF"), std::string::npos) << sent.error();
  EXPECT_FALSE(sender.connected());
}

TEST(IgtlTransformSender, ServerThatClosedTheConnectionFailsTheSend) {
  IgtlTestReceiver receiver(IgtlTestReceiver::Behaviour::CloseOnAccept);
  ASSERT_GT(receiver.port(), 0);
  IgtlTransformSender sender({"127.0.0.1", receiver.port()}, "FluoroCT");
  ASSERT_TRUE(sender.connect().ok());
  EXPECT_TRUE(receiver.received().empty());  // returns once the server has closed its side
  const Status sent = sender.send(nonSymmetricPose());
  ASSERT_FALSE(sent.ok());
  EXPECT_NE(sent.error().find("closed the connection"), std::string::npos) << sent.error();
  EXPECT_FALSE(sender.connected());
}

TEST(IgtlTransformSender, ConnectTimesOutWhenTheServerNeverAccepts) {
  // A listening socket with a full backlog that nobody accepts from: the kernel drops further SYNs, so connect()
  // waits until the sender's timeout.
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(::listen(fd, 0), 0);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  const IgtlEndpoint endpoint{"127.0.0.1", ntohs(address.sin_port)};
  std::vector<std::unique_ptr<IgtlTransformSender>> queued;
  Status last = Ok{};
  for (int n = 0; n < 8 && last.ok(); ++n) {
    queued.push_back(std::make_unique<IgtlTransformSender>(endpoint, "FluoroCT", std::chrono::milliseconds(200)));
    last = queued.back()->connect();
  }
  ::close(fd);
  ASSERT_FALSE(last.ok());
  EXPECT_NE(last.error().find("no answer within 0.2 s"), std::string::npos) << last.error();
}

TEST(IgtlTransformSender, ParsesHostAndPortAndRefusesMalformedOnes) {
  auto parsed = IgtlTransformSender::parseEndpoint("localhost:18944");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().host, "localhost");
  EXPECT_EQ(parsed.value().port, 18944);
  auto v6 = IgtlTransformSender::parseEndpoint("[::1]:18945");
  ASSERT_TRUE(v6.ok()) << v6.error();
  EXPECT_EQ(v6.value().host, "::1");
  EXPECT_EQ(v6.value().text(), "[::1]:18945");
  for (const char* bad : {"localhost", ":18944", "localhost:", "localhost:0", "localhost:70000", "host:12ab", "::1:5"}) {
    const auto result = IgtlTransformSender::parseEndpoint(bad);
    EXPECT_FALSE(result.ok()) << bad;
    EXPECT_NE(result.error().find(bad), std::string::npos) << result.error();
  }
}

TEST(IgtlTransformSender, RefusesDeviceNamesTheHeaderCannotHoldBeforeConnecting) {
  EXPECT_TRUE(IgtlTransformSender::checkDeviceName("FluoroCT").ok());
  EXPECT_FALSE(IgtlTransformSender::checkDeviceName("").ok());
  EXPECT_FALSE(IgtlTransformSender::checkDeviceName("A-device-name-too-long").ok());
  EXPECT_FALSE(IgtlTransformSender::checkDeviceName("tab\there").ok());
  IgtlTransformSender sender({"127.0.0.1", IgtlTestReceiver::unusedPort()}, "");
  const Status sent = sender.send(Eigen::Isometry3d::Identity());
  ASSERT_FALSE(sent.ok());
  EXPECT_NE(sent.error().find("device name"), std::string::npos) << sent.error();
}

}  // namespace
}  // namespace fct
