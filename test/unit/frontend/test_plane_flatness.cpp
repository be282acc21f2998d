// The plane stage's flatness test on whole regions (PlaneRegionGrower::grow): a curved surface
// 2-3 m away, whose normals scatter as much as they bend across a narrow strip, must not end up as
// a plane once the strip is merged and filled out over its visible side; flat surfaces stay planes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/sim/kinect_depth_model.h"
#include "quadric_slam/sim/primitive_scene_renderer.h"
#include "segment_rendered.h"

namespace qs = quadric_slam;
using qs::PrimitiveShape;
using qs::QuadricClass;

namespace {

// A floor 1 m below the camera (y is down), a wall 3.2 m ahead, and a cone standing on the floor at
// `range` like a traffic cone: apex 0.75 m above the floor, axis down, half angle 0.32 rad, its
// surface 0.1-0.75 m along the axis (0.65 m high, 0.03-0.25 m in radius).
std::vector<qs::ScenePrimitive> coneScene(double range) {
  std::vector<qs::ScenePrimitive> scene(3);
  scene[0].shape = PrimitiveShape::plane(Eigen::Vector3d(0, -1, 0), -1.0);
  scene[1].shape = PrimitiveShape::plane(Eigen::Vector3d(0, 0, -1), -3.2);
  scene[2].shape =
      PrimitiveShape::cone(Eigen::Vector3d(0.2, 0.25, range), Eigen::Vector3d(0, 1, 0), 0.32);
  scene[2].axis_min = 0.1;
  scene[2].axis_max = 0.75;
  return scene;
}

// The share of the primitive's pixels that the largest plane segment on them covers.
double planeShareOn(const qs::Segmentation& result, const cv::Mat& truth, int t) {
  int total = 0;
  const std::vector<int> count = qs::test::labelCountsOn(result, truth, t, &total);
  int largest = 0;
  for (const qs::QuadricDetection& d : result.detections)
    if (d.shape.quadric_class == QuadricClass::kPlane)
      largest = std::max(largest, count[d.label]);
  return total > 0 ? static_cast<double>(largest) / total : 0.0;
}

// The rendering through the simulator's harsh Kinect v1 model (sim/kinect_depth_model.h): axial
// noise as measured on real frames, spatially correlated, quantised, with the radial distortion.
cv::Mat harshDepth(const std::vector<qs::ScenePrimitive>& scene,
                   const qs::PrimitiveRendering& ideal, std::uint64_t seed) {
  const qs::CameraIntrinsics k = qs::test::kinectVga();
  cv::Mat cos_incidence(ideal.depth.size(), CV_32FC1, cv::Scalar(1.0f));
  for (int v = 0; v < ideal.depth.rows; ++v)
    for (int u = 0; u < ideal.depth.cols; ++u) {
      const float z = ideal.depth.at<float>(v, u);
      const std::uint16_t t = ideal.truth.at<std::uint16_t>(v, u);
      if (!std::isfinite(z) || t == 0)
        continue;
      const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const Eigen::Vector3d normal = scene[t - 1].shape.normalAt(z * ray);
      cos_incidence.at<float>(v, u) = static_cast<float>(std::abs(normal.dot(ray.normalized())));
    }
  return qs::KinectDepthModel().apply(ideal.depth, cos_incidence, seed);
}

TEST(PlaneFlatness, AFarConeIsNoPlane) {
  qs::RenderParams ideal_render;
  ideal_render.noise_factor = 0.0;
  const std::vector<qs::ScenePrimitive> scene = coneScene(2.4);
  const qs::PrimitiveRendering ideal =
      qs::renderPrimitives(scene, qs::test::kinectVga(), ideal_render);
  int planes = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const qs::Segmentation result = qs::test::segmentRendered(harshDepth(scene, ideal, seed));
    const double share = planeShareOn(result, ideal.truth, 2);
    std::printf("seed %lu: cone %.2f floor %.2f wall %.2f\n", static_cast<unsigned long>(seed),
                share, planeShareOn(result, ideal.truth, 0), planeShareOn(result, ideal.truth, 1));
    planes += share > 0.1;
    // The floor and the wall stay one plane each.
    EXPECT_GE(planeShareOn(result, ideal.truth, 0), 0.8) << "seed " << seed;
    EXPECT_GE(planeShareOn(result, ideal.truth, 1), 0.8) << "seed " << seed;
  }
  EXPECT_EQ(planes, 0) << "the cone's side taken as a plane in " << planes << " of 6 frames";
}

}  // namespace
