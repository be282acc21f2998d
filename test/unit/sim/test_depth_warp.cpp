// sim/depth_warp.h: a depth image re-projected into a moved camera keeps its points on the measured
// surface, leaves disoccluded areas empty and hides what a nearer surface covers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "../kinect_vga.h"
#include "../real_frames.h"
#include "quadric_slam/sim/depth_warp.h"

namespace qs = quadric_slam;

namespace {

struct RealFrame {
  cv::Mat depth;
  qs::CameraIntrinsics k;
};

RealFrame fr3Frame() {
  RealFrame f;
  f.depth = qs::readTumDepthPng(qs::test::shippedData(qs::test::kFr3HouseholdDepth).string());
  f.k = qs::tumIntrinsicsForSequence("fr3_long_office_household");
  f.k.width = f.depth.cols;
  f.k.height = f.depth.rows;
  return f;
}

Eigen::Isometry3d motion(const Eigen::Vector3d& t, double angle_deg, const Eigen::Vector3d& axis) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle_deg * M_PI / 180, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

bool valid(float z) {
  return std::isfinite(z) && z > 0;
}

}  // namespace

// Every depth of the warped image, taken back to the reference camera, lies on the reference
// surface: its pixel there falls in a 2 x 2 block of measured pixels and its depth between theirs
// (a triangle's points lie between its corners' depths).
TEST(DepthWarp, WarpedPixelsReprojectOntoTheMeasuredSurface) {
  const RealFrame f = fr3Frame();
  const Eigen::Isometry3d T_ref_moved =
      motion(Eigen::Vector3d(0.08, -0.05, 0.10), 12.0, Eigen::Vector3d(0.3, 1.0, 0.2));
  const cv::Mat warped = qs::warpDepthImage(f.depth, f.k, T_ref_moved);

  int checked = 0, reference_valid = 0;
  for (int v = 0; v < f.depth.rows; ++v)
    for (int u = 0; u < f.depth.cols; ++u)
      reference_valid += valid(f.depth.at<float>(v, u));
  for (int v = 0; v < warped.rows; ++v) {
    for (int u = 0; u < warped.cols; ++u) {
      const float z = warped.at<float>(v, u);
      if (!valid(z))
        continue;
      const Eigen::Vector3d p_moved((u - f.k.cx) * z / f.k.fx, (v - f.k.cy) * z / f.k.fy, z);
      const Eigen::Vector3d p = T_ref_moved * p_moved;
      const double ur = f.k.fx * p.x() / p.z() + f.k.cx, vr = f.k.fy * p.y() / p.z() + f.k.cy;
      const int u0 = static_cast<int>(std::floor(ur + 1e-6)),
                v0 = static_cast<int>(std::floor(vr + 1e-6));
      ASSERT_TRUE(u0 >= 0 && v0 >= 0 && u0 < f.depth.cols && v0 < f.depth.rows)
          << "warped pixel " << u << "," << v << " comes from outside the reference image";
      float lo = std::numeric_limits<float>::max(), hi = 0;
      int corners = 0;
      for (int dv = 0; dv <= 1; ++dv)
        for (int du = 0; du <= 1; ++du) {
          const int uu = std::min(u0 + du, f.depth.cols - 1),
                    vv = std::min(v0 + dv, f.depth.rows - 1);
          const float zr = f.depth.at<float>(vv, uu);
          if (!valid(zr))
            continue;
          ++corners;
          lo = std::min(lo, zr);
          hi = std::max(hi, zr);
        }
      ASSERT_GE(corners, 3) << "warped pixel " << u << "," << v << " has no measured surface";
      EXPECT_GE(p.z(), lo - 1e-3) << "at " << u << "," << v;
      EXPECT_LE(p.z(), hi + 1e-3) << "at " << u << "," << v;
      ++checked;
    }
  }
  // A 10-15 cm, 12-degree motion keeps most of a room-scale view in sight.
  EXPECT_GT(checked, reference_valid / 2);
}

// The identity motion gives the image back wherever a pixel belongs to a continuous 2 x 2 block,
// and never invents depth where there was none.
TEST(DepthWarp, IdentityMotionReproducesTheFrame) {
  const RealFrame f = fr3Frame();
  const cv::Mat warped = qs::warpDepthImage(f.depth, f.k, Eigen::Isometry3d::Identity());
  int same = 0, reference_valid = 0;
  for (int v = 0; v < f.depth.rows; ++v) {
    for (int u = 0; u < f.depth.cols; ++u) {
      const float zr = f.depth.at<float>(v, u), zw = warped.at<float>(v, u);
      reference_valid += valid(zr);
      if (!valid(zr)) {
        EXPECT_FALSE(valid(zw)) << "depth invented at " << u << "," << v;
        continue;
      }
      if (valid(zw)) {
        EXPECT_NEAR(zw, zr, 1e-4 * zr) << "at " << u << "," << v;
        ++same;
      }
    }
  }
  // Only pixels on no continuous triangle (isolated, or at every neighbour a depth jump) are lost.
  EXPECT_GT(same, 0.97 * reference_valid);
}

// A square at 1 m before a wall at 3 m, camera moved 20 cm to the right: the square shifts 105
// pixels left, the wall 35; the strip of wall the square hid in the reference is a hole (nothing
// is filled in), the square hides the wall behind it (z-buffer), and what lies beyond the
// reference image's right edge is a hole too.
TEST(DepthWarp, DisoccludedAreasAreHolesAndNearerSurfacesHideFartherOnes) {
  const qs::CameraIntrinsics k = qs::test::kinectVga();
  cv::Mat depth(k.height, k.width, CV_32FC1, cv::Scalar(3.0f));
  depth(cv::Rect(280, 200, 81, 81)).setTo(1.0f);  // u 280..360, v 200..280
  const Eigen::Isometry3d T_ref_moved =
      motion(Eigen::Vector3d(0.2, 0, 0), 0, Eigen::Vector3d::UnitZ());
  const cv::Mat w = qs::warpDepthImage(depth, k, T_ref_moved);

  for (int v = 205; v <= 275; ++v) {
    for (int u = 180; u <= 250; ++u)  // the square (now at u 175..255), in front of the wall
      ASSERT_NEAR(w.at<float>(v, u), 1.0f, 1e-4) << "at " << u << "," << v;
    for (int u = 260; u <= 320; ++u)  // wall hidden behind the square in the reference: a hole
      ASSERT_FALSE(valid(w.at<float>(v, u))) << "disoccluded pixel filled at " << u << "," << v;
  }
  for (int v = 20; v <= 460; v += 10) {
    for (int u = 400; u <= 600; u += 10)  // wall seen in both
      ASSERT_NEAR(w.at<float>(v, u), 3.0f, 1e-4) << "at " << u << "," << v;
    for (int u = 606; u < k.width; ++u)  // beyond the reference image's edge
      ASSERT_FALSE(valid(w.at<float>(v, u))) << "unseen pixel filled at " << u << "," << v;
  }
}

TEST(DepthWarp, RejectsBadInputAndParameters) {
  const qs::CameraIntrinsics k = qs::test::kinectVga();
  const cv::Mat depth(k.height, k.width, CV_32FC1, cv::Scalar(2.0f));
  qs::DepthWarpParams p;
  p.depth_jump_fraction = 0;
  try {
    qs::warpDepthImage(depth, k, Eigen::Isometry3d::Identity(), p);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("depth_jump_fraction"), std::string::npos);
  }
  EXPECT_THROW(qs::warpDepthImage(cv::Mat(10, 10, CV_32FC1, cv::Scalar(1.0f)), k,
                                  Eigen::Isometry3d::Identity()),
               std::invalid_argument);
  EXPECT_THROW(
      qs::warpDepthImage(cv::Mat(k.height, k.width, CV_16UC1), k, Eigen::Isometry3d::Identity()),
      std::invalid_argument);
}
