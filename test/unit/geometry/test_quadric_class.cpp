#include <gtest/gtest.h>

#include <stdexcept>

#include "quadric_slam/geometry/quadric_class.h"

using quadric_slam::QuadricClass;

TEST(QuadricClass, NamesRoundTrip) {
  for (QuadricClass c : quadric_slam::kAllQuadricClasses) {
    EXPECT_EQ(quadric_slam::quadricClassFromString(quadric_slam::toString(c)), c);
    EXPECT_EQ(quadric_slam::quadricClassFromInt(static_cast<int>(c)), c);
  }
  EXPECT_THROW(quadric_slam::quadricClassFromString("torus"), std::invalid_argument);
  EXPECT_THROW(quadric_slam::quadricClassFromInt(5), std::invalid_argument);
  EXPECT_THROW(quadric_slam::quadricClassFromInt(-1), std::invalid_argument);
}

TEST(QuadricClass, SignaturesFollowTableTwo) {
  EXPECT_EQ(quadric_slam::defaultSignature(QuadricClass::kPlane), Eigen::Vector4d(1, 0, 0, 0));
  EXPECT_EQ(quadric_slam::defaultSignature(QuadricClass::kSphere), Eigen::Vector4d(1, 1, 1, -1));
  EXPECT_EQ(quadric_slam::defaultSignature(QuadricClass::kCylinder), Eigen::Vector4d(1, 1, 0, -1));
  EXPECT_EQ(quadric_slam::defaultSignature(QuadricClass::kCone), Eigen::Vector4d(1, 1, -1, 0));
}

TEST(QuadricClass, MinimalDimensionsFollowTableTwo) {
  EXPECT_EQ(quadric_slam::minimalDimension(QuadricClass::kPlane), 3);
  EXPECT_EQ(quadric_slam::minimalDimension(QuadricClass::kSphere), 4);
  EXPECT_EQ(quadric_slam::minimalDimension(QuadricClass::kCylinder), 5);
  EXPECT_EQ(quadric_slam::minimalDimension(QuadricClass::kCone), 6);
  EXPECT_EQ(quadric_slam::minimalDimension(QuadricClass::kGeneral), 9);
}
