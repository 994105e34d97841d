#include <gtest/gtest.h>

#include <cmath>

#include "Geometry/DewarpField.h"

namespace {

/// A degree-3 field with a pincushion-like correction (ideal = d − 0.02 R ρ² (x, y)).
fct::DewarpField cubicField() {
  const auto terms = fct::DewarpField::terms(3);
  Eigen::VectorXd col = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(terms.size()));
  Eigen::VectorXd row = col;
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const auto i = static_cast<Eigen::Index>(t);
    if (terms[t] == std::array<int, 2>{3, 0} || terms[t] == std::array<int, 2>{1, 2}) col[i] = -0.02;
    if (terms[t] == std::array<int, 2>{0, 3} || terms[t] == std::array<int, 2>{2, 1}) row[i] = -0.02;
  }
  return fct::DewarpField::create(200, 150, 3, col, row).value();
}

}  // namespace

TEST(DewarpField, IdentityFieldLeavesEveryPixelWhereItIs) {
  auto field = fct::DewarpField::identity(200, 150, 4);
  ASSERT_TRUE(field.ok()) << field.error();
  for (const Eigen::Vector2d& uv : {Eigen::Vector2d(0, 0), Eigen::Vector2d(199, 149), Eigen::Vector2d(37.3, 80.9)}) {
    EXPECT_LT((field.value().ideal(uv) - uv).norm(), 1e-12);
    EXPECT_LT((field.value().distorted(uv).value() - uv).norm(), 1e-12);
  }
  EXPECT_EQ(field.value().terms(4).size(), 12u);  // 3 quadratic + 4 cubic + 5 quartic
}

TEST(DewarpField, DistortedInvertsIdealAndTheCentreIsFixed) {
  const fct::DewarpField field = cubicField();
  EXPECT_LT((field.ideal(field.centre_px()) - field.centre_px()).norm(), 1e-12);
  EXPECT_LT((field.jacobian(field.centre_px()) - Eigen::Matrix2d::Identity()).norm(), 1e-12);
  for (const Eigen::Vector2d& u : {Eigen::Vector2d(3, 4), Eigen::Vector2d(190, 140), Eigen::Vector2d(120.25, 20.5)}) {
    const auto d = field.distorted(u);
    ASSERT_TRUE(d.has_value());
    EXPECT_LT((field.ideal(*d) - u).norm(), 1e-6);
  }
  // The analytic Jacobian agrees with central differences.
  const Eigen::Vector2d p(150.0, 30.0);
  const double h = 1e-4;
  Eigen::Matrix2d numeric;
  numeric.col(0) = (field.ideal(p + Eigen::Vector2d(h, 0)) - field.ideal(p - Eigen::Vector2d(h, 0))) / (2 * h);
  numeric.col(1) = (field.ideal(p + Eigen::Vector2d(0, h)) - field.ideal(p - Eigen::Vector2d(0, h))) / (2 * h);
  EXPECT_LT((field.jacobian(p) - numeric).norm(), 1e-7);
}

TEST(DewarpField, RejectsBadSizesDegreesAndCoefficients) {
  EXPECT_FALSE(fct::DewarpField::identity(0, 100, 3).ok());
  EXPECT_FALSE(fct::DewarpField::identity(100, 100, 1).ok());
  EXPECT_FALSE(fct::DewarpField::identity(100, 100, 10).ok());
  EXPECT_FALSE(fct::DewarpField::create(100, 100, 3, Eigen::VectorXd::Zero(6), Eigen::VectorXd::Zero(7)).ok());
  Eigen::VectorXd bad = Eigen::VectorXd::Zero(7);
  bad[2] = std::nan("");
  auto nan = fct::DewarpField::create(100, 100, 3, bad, Eigen::VectorXd::Zero(7));
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().find("finite"), std::string::npos) << nan.error();
}
