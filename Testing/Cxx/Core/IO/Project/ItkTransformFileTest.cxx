#include <gtest/gtest.h>

#include <sstream>

#include "Base/TextFile.h"
#include "IO/Project/ItkTransformFile.h"
#include "TestSupport.h"

namespace {

Eigen::Isometry3d obliquePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(-1.1, Eigen::Vector3d(0.3, 0.4, 1.0).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(25.5, -130.0, 842.75);
  return T;
}

fct::Result<Eigen::Isometry3d> readText(const std::string& text) {
  const auto path = fct::test::scratchDir() / "pose.tfm";
  EXPECT_TRUE(fct::TextFile::writeAtomically(path, text).ok());
  return fct::ItkTransformFile::read(path);
}

std::string withParameters(const std::string& type, const std::string& parameters, const std::string& fixed) {
  return "#Insight Transform File V1.0\n#Transform 0\nTransform: " + type + "\nParameters: " + parameters +
         "\nFixedParameters: " + fixed + "\n";
}

}  // namespace

TEST(ItkTransformFile, RoundTripsAnObliquePose) {
  const auto path = fct::test::scratchDir() / "pose.tfm";
  ASSERT_TRUE(fct::ItkTransformFile::write(obliquePose(), path).ok());
  const auto read = fct::ItkTransformFile::read(path);
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_LT((read.value().matrix() - obliquePose().matrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ItkTransformFile, StoresTheInverseResamplingTransformInLps) {
  const auto path = fct::test::scratchDir() / "pose.tfm";
  ASSERT_TRUE(fct::ItkTransformFile::write(obliquePose(), path).ok());
  std::istringstream lines(fct::TextFile::read(path).value());
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "#Insight Transform File V1.0");
  std::getline(lines, line);
  EXPECT_EQ(line, "#Transform 0");
  std::getline(lines, line);
  EXPECT_EQ(line, "Transform: AffineTransform_double_3_3");
  std::getline(lines, line);
  ASSERT_EQ(line.rfind("Parameters: ", 0), 0u) << line;
  std::istringstream numbers(line.substr(12));
  const Eigen::Isometry3d T_ct_from_world = obliquePose().inverse();
  for (int i = 0; i < 12; ++i) {
    double value = 0.0;
    ASSERT_TRUE(numbers >> value);
    const double expected = i < 9 ? T_ct_from_world.linear()(i / 3, i % 3) : T_ct_from_world.translation()(i - 9);
    EXPECT_NEAR(value, expected, 1e-12) << "parameter " << i;
  }
  std::getline(lines, line);
  EXPECT_EQ(line, "FixedParameters: 0 0 0");
}

TEST(ItkTransformFile, ReadsATransformWithACentreOfRotation) {
  // y = A (x - c) + t + c with A a 90 degree turn about z, c = (10, 0, 0), t = (1, 2, 3) (this is T_ct_from_world).
  const auto read = readText(withParameters("AffineTransform_float_3_3", "0 -1 0 1 0 0 0 0 1 1 2 3", "10 0 0"));
  ASSERT_TRUE(read.ok()) << read.error();
  const Eigen::Vector3d p_world(4, 5, 6);
  const Eigen::Vector3d p_ct = read.value().inverse() * p_world;
  EXPECT_LT((p_ct - Eigen::Vector3d(-5 + 1 + 10, -6 + 2, 6 + 3)).norm(), 1e-12) << p_ct.transpose();
}

TEST(ItkTransformFile, RejectsBadFiles) {
  const std::string identity = "1 0 0 0 1 0 0 0 1 0 0 0";
  auto read = readText(withParameters("AffineTransform_double_3_3", "2 0 0 0 1 0 0 0 1 0 0 0", "0 0 0"));
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("not a rigid transform"), std::string::npos) << read.error();
  read = readText(withParameters("AffineTransform_double_3_3", "1 0 0 0 1 0 0 0 1 0 0", "0 0 0"));
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("expected 12 Parameters"), std::string::npos) << read.error();
  read = readText(withParameters("AffineTransform_double_3_3", "1 0 0 0 1 0 0 0 1 nan 0 0", "0 0 0"));
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("NaN"), std::string::npos) << read.error();
  read = readText(withParameters("AffineTransform_double_3_3", "1 0 0 0 1 0 0 0 1 x 0 0", "0 0 0"));
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("'x' is not a number"), std::string::npos) << read.error();
  read = readText(withParameters("BSplineTransform_double_3_3", identity, "0 0 0"));
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("'BSplineTransform_double_3_3' is not supported"), std::string::npos) << read.error();
  read = readText(withParameters("AffineTransform_double_3_3", identity, "0 0 0") +
                  "#Transform 1\nTransform: AffineTransform_double_3_3\n");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("holds 2 transforms"), std::string::npos) << read.error();
  read = readText("Parameters: " + identity + "\n");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("not an ITK transform file"), std::string::npos) << read.error();
}

TEST(ItkTransformFile, WriteRejectsANonRigidPoseAndAnUnwritablePath) {
  const auto dir = fct::test::scratchDir();
  Eigen::Isometry3d scaled = obliquePose();
  scaled.matrix().topLeftCorner<3, 3>() *= 1.1;
  EXPECT_FALSE(fct::ItkTransformFile::write(scaled, dir / "pose.tfm").ok());
  const auto status = fct::ItkTransformFile::write(obliquePose(), dir / "missing" / "pose.tfm");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("missing/pose.tfm"), std::string::npos) << status.error();
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}
