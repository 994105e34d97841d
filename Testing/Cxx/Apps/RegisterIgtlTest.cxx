// fluoroct register --igtl: the registered pose reaches a loopback OpenIGTLink server (IgtlTestReceiver, standing in
// for 3D Slicer's OpenIGTLinkIF) as a TRANSFORM in RAS; a refused port or a server that closed the connection gives
// one error naming --igtl, exit status 3, and the result file written and intact.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include "Base/JsonDocument.h"
#include "IgtlTestReceiver.h"
#include "Interop/IgtlTransformSender.h"
#include "IO/Project/PoseFile.h"
#include "SimulatedCliCase.h"

namespace {

namespace fs = std::filesystem;

/// The register command line on the simulated case in `dir` (fast preset, local searches), writing result.json.
std::string registerCommand(const fs::path& dir) {
  return fmt::format("register --ct '{}' --views '{}' --init '{}' --preset fast --local-only --out '{}'",
                     (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(), (dir / "init.json").string(),
                     (dir / "result.json").string());
}

/// Makes the case and its start pose in a fresh scratch folder.
fs::path preparedCase() {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = fct::test::makeCase(dir);
  EXPECT_TRUE(fct::PoseFile::write(fct::test::perturbed(truth), dir / "init.json").ok());
  return dir;
}

/// The result file was written completely: it parses and holds the registered pose.
void expectResultIntact(const fs::path& dir) {
  auto json = fct::JsonDocument::parse(dir / "result.json");
  ASSERT_TRUE(json.ok()) << json.error();
  EXPECT_FALSE(json.value()["cancelled"].get<bool>());
  EXPECT_TRUE(fct::PoseFile::read(dir / "result.json").ok());
}

}  // namespace

TEST(RegisterCommand, SendsTheRegisteredPoseToAnOpenIgtLinkServerInRas) {
  const fs::path dir = preparedCase();
  constexpr int kStages = 4;  // the fast preset
  fct::test::IgtlTestReceiver receiver(fct::test::IgtlTestReceiver::Behaviour::Record, kStages + 1);
  ASSERT_GT(receiver.port(), 0);
  const auto run = fct::test::runCli(registerCommand(dir) +
                                     fmt::format(" --igtl {} --igtl-device FemurPose --igtl-progress", receiver.endpoint()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.out.find("sent the pose to the OpenIGTLink server at " + receiver.endpoint() + " as TRANSFORM 'FemurPose'"),
            std::string::npos)
      << run.out;
  const std::vector<fct::test::ReceivedTransform> received = receiver.received();
  fct::test::IgtlTestReceiver::print(received);
  ASSERT_EQ(received.size(), static_cast<std::size_t>(kStages + 1)) << "one per stage, then the final pose";
  for (const auto& transform : received) EXPECT_EQ(transform.deviceName, "FemurPose");
  auto registered = fct::PoseFile::read(dir / "result.json");
  ASSERT_TRUE(registered.ok()) << registered.error();
  const Eigen::Matrix4d expected = fct::IgtlTransformSender::rasFromLps(registered.value());
  EXPECT_TRUE(received.back().matrix.isApprox(expected, 1e-5)) << received.back().matrix << "\nvs\n" << expected;
  EXPECT_TRUE(received[kStages - 1].matrix.isApprox(expected, 1e-5)) << "the last stage ends at the final pose";
}

TEST(RegisterCommand, RefusedOpenIgtLinkPortKeepsTheResultAndExitsWith3) {
  const fs::path dir = preparedCase();
  const int port = fct::test::IgtlTestReceiver::unusedPort();
  ASSERT_GT(port, 0);
  const std::string endpoint = fmt::format("127.0.0.1:{}", port);
  const auto run = fct::test::runCli(registerCommand(dir) + " --igtl " + endpoint);
  EXPECT_EQ(run.exitCode, 3) << run.err;
  EXPECT_NE(run.err.find("warning: --igtl: cannot connect to the OpenIGTLink server at " + endpoint +
                         ": connection refused"),
            std::string::npos)
      << "told before registering: " << run.err;
  EXPECT_NE(run.err.find("error: --igtl: the registered pose was not sent"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("the result is kept in " + (dir / "result.json").string()), std::string::npos) << run.err;
  EXPECT_NE(run.out.find("registered"), std::string::npos) << run.out;
  expectResultIntact(dir);
}

TEST(RegisterCommand, OpenIgtLinkServerThatClosesEarlyKeepsTheResultAndExitsWith3) {
  const fs::path dir = preparedCase();
  fct::test::IgtlTestReceiver receiver(fct::test::IgtlTestReceiver::Behaviour::CloseOnAccept);
  ASSERT_GT(receiver.port(), 0);
  const auto run = fct::test::runCli(registerCommand(dir) + " --igtl " + receiver.endpoint());
  EXPECT_EQ(run.exitCode, 3) << run.err;
  EXPECT_NE(run.err.find("error: --igtl: the registered pose was not sent: the OpenIGTLink server at " +
                         receiver.endpoint() + " closed the connection"),
            std::string::npos)
      << run.err;
  EXPECT_TRUE(receiver.received().empty());
  expectResultIntact(dir);
}

TEST(RegisterCommand, RefusesABadOpenIgtLinkAddressOrDeviceBeforeRegistering) {
  const fs::path dir = fct::test::scratchDir();  // no case: the link is checked before any input is read
  const auto badAddress = fct::test::runCli(registerCommand(dir) + " --igtl localhost");
  EXPECT_TRUE(fct::test::oneErrorLine(badAddress)) << badAddress.err;
  EXPECT_NE(badAddress.err.find("--igtl: 'localhost' is not HOST:PORT"), std::string::npos) << badAddress.err;
  const auto badDevice = fct::test::runCli(registerCommand(dir) + " --igtl localhost:18944 --igtl-device ''");
  EXPECT_TRUE(fct::test::oneErrorLine(badDevice)) << badDevice.err;
  EXPECT_NE(badDevice.err.find("--igtl-device"), std::string::npos) << badDevice.err;
  EXPECT_EQ(badDevice.err.find("--ct"), std::string::npos) << "refused before the inputs: " << badDevice.err;
  EXPECT_FALSE(fs::exists(dir / "result.json")) << "nothing registered, nothing written";
}
