// The segmenter on an open, uncapped cylinder (a waste bin: radius 15 cm, 35 cm tall, standing on a
// floor) rendered by the synthetic generator's ray caster with its Kinect depth model, seen from
// the side and from above (the inside visible), cut by the image edge and about 2.5 m away, where
// the depth noise and quantisation hide the sag of the visible arc. It must be found as a cylinder
// with a radius error of at most 5 mm (median over the views and noise seeds).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/sim/renderer.h"
#include "quadric_slam/sim/scene.h"
#include "quadric_slam/sim/surfaces.h"
#include "quadric_slam/sim/trajectory.h"

namespace qs = quadric_slam;

namespace {

constexpr double kRadius = 0.15;
const Eigen::Vector3d kBinCentre(0.0, 0.0, 0.175);

// A floor (rectangle: normal = local x, turned to world +z) and the open bin on it.
qs::Scene binScene() {
  qs::Scene scene;
  qs::PrimitiveSpec floor;
  floor.name = "floor";
  floor.type = qs::PrimitiveType::kRectangle;
  floor.size = Eigen::Vector3d(0, 8, 8);
  floor.T_world_primitive.linear() =
      Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  scene.primitives.push_back(floor);
  qs::PrimitiveSpec bin;
  bin.name = "bin";
  bin.type = qs::PrimitiveType::kCylinder;
  bin.T_world_primitive.translation() = kBinCentre;  // axis = world z
  bin.radius = kRadius;
  bin.length = 0.35;
  bin.capped = false;
  scene.primitives.push_back(bin);
  return scene;
}

struct View {
  const char* name;
  Eigen::Vector3d eye;  // world (m)
  // The camera looks past the bin by these angles (deg): the bin moves towards the image's left
  // edge (yaw) and bottom edge (pitch).
  double yaw, pitch;
};

Eigen::Isometry3d cameraPose(const View& view) {
  const Eigen::Vector3d d = kBinCentre - view.eye;
  const double azimuth = std::atan2(d.y(), d.x()) - view.yaw * M_PI / 180;
  const double elevation = std::atan2(d.z(), d.head<2>().norm()) + view.pitch * M_PI / 180;
  const Eigen::Vector3d forward(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  return qs::lookAt(view.eye, view.eye + forward);
}

}  // namespace

TEST(QuadricSegmenterOpenCylinder, FarOpenBinCutByTheImageEdgeIsACylinder) {
  const qs::Scene scene = binScene();
  const std::vector<qs::Surface> surfaces = qs::buildSurfaces(scene);
  int bin_id = 0;
  for (const qs::Surface& s : surfaces)
    if (s.name() == "bin")
      bin_id = s.id();
  ASSERT_GT(bin_id, 0);
  const qs::CameraIntrinsics camera = scene.camera;
  // Kept on the independent-noise (nguyen) depth model: under the harsh default model this view
  // fails today (issue 11's segmentation work), which this test is not about.
  const qs::Renderer renderer(surfaces, camera, qs::KinectDepthModel::nguyenParams(),
                              qs::Renderer::Params());
  const qs::NormalEstimator normals{qs::NormalEstimator::Params()};
  const qs::QuadricSegmenter segmenter{qs::QuadricSegmenter::Params()};

  const std::vector<View> views = {
      // From the side and a little above, 2.45 m away, cut by the left image edge: a strip of the
      // outer wall about a third of the bin wide (~3900 pixels).
      {"side, left edge", Eigen::Vector3d(2.2, -0.44, 0.99), 34, 0},
      // From above, 2.46 m away: the outer wall and, over the rim, the inner far wall, whose
      // normals point the other way relative to the axis; cut by the bottom image edge.
      {"above, bottom edge", Eigen::Vector3d(1.4, 0.3, 2.0), 0, 22},
  };
  std::vector<double> radius_errors;
  int detected = 0, rendered = 0;
  for (const View& view : views) {
    const Eigen::Isometry3d T_world_camera = cameraPose(view);
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const qs::RenderedFrame frame = renderer.render(T_world_camera, seed);
      int bin_pixels = 0, on_edge = 0;
      for (int v = 0; v < frame.labels.rows; ++v)
        for (int u = 0; u < frame.labels.cols; ++u)
          if (frame.labels.at<std::uint16_t>(v, u) == bin_id) {
            ++bin_pixels;
            on_edge += u == 0 || v == 0 || u + 1 == frame.labels.cols || v + 1 == frame.labels.rows;
          }
      // The view is what it claims: enough of the bin, cut by the image edge.
      ASSERT_GE(bin_pixels, 2000) << view.name;
      ASSERT_GT(on_edge, 0) << view.name;
      ++rendered;

      qs::DepthImageView<float> depth;
      depth.data = frame.depth.data;
      depth.width = frame.depth.cols;
      depth.height = frame.depth.rows;
      depth.row_step_bytes = frame.depth.step[0];
      const qs::Segmentation result = segmenter.segment(
          normals.compute(qs::backProject(depth, camera, qs::BackProjectionParams())));
      // The detection with most pixels on the bin.
      std::map<int, int> overlap;
      for (int v = 0; v < frame.labels.rows; ++v)
        for (int u = 0; u < frame.labels.cols; ++u)
          if (frame.labels.at<std::uint16_t>(v, u) == bin_id &&
              result.labels.at<std::uint16_t>(v, u))
            ++overlap[result.labels.at<std::uint16_t>(v, u)];
      const auto best = std::max_element(overlap.begin(), overlap.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      const qs::QuadricDetection* detection =
          best == overlap.end() ? nullptr : &result.detections[best->first - 1];
      const bool cylinder =
          detection && detection->shape.quadric_class == qs::QuadricClass::kCylinder;
      const Eigen::Vector3d axis_world =
          cylinder ? Eigen::Vector3d(T_world_camera.linear() * detection->shape.direction)
                   : Eigen::Vector3d::Zero();
      std::printf("%-20s seed %d: %d bin pixels, %s", view.name, static_cast<int>(seed), bin_pixels,
                  cylinder    ? "cylinder"
                  : detection ? "other class"
                              : "nothing");
      if (cylinder) {
        const double error = std::abs(detection->shape.size - kRadius);
        std::printf(" radius %.4f m, axis tilt %.2f deg, %d of its points on the bin",
                    detection->shape.size,
                    std::acos(std::min(1.0, std::abs(axis_world.z()))) * 180 / M_PI, best->second);
        radius_errors.push_back(error);
        ++detected;
      }
      std::printf("\n");
      EXPECT_TRUE(cylinder) << view.name << ", seed " << seed;
    }
  }
  ASSERT_EQ(detected, rendered);
  std::nth_element(radius_errors.begin(), radius_errors.begin() + radius_errors.size() / 2,
                   radius_errors.end());
  EXPECT_LE(radius_errors[radius_errors.size() / 2], 0.005);
}
