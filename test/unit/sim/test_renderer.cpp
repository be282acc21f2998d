#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "quadric_slam/sim/renderer.h"
#include "quadric_slam/sim/surfaces.h"
#include "quadric_slam/sim/trajectory.h"

using namespace quadric_slam;

namespace {

const CameraIntrinsics kCamera{262.5, 262.5, 159.5, 119.5, 320, 240};

PrimitiveSpec sphereAt(const Eigen::Vector3d& centre, double radius) {
  PrimitiveSpec s;
  s.name = "ball";
  s.type = PrimitiveType::kSphere;
  s.radius = radius;
  s.T_world_primitive.translation() = centre;
  return s;
}

// A rectangle through `point` with unit normal `normal` (large enough to fill the view).
PrimitiveSpec planeAt(const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  PrimitiveSpec p;
  p.name = "plane";
  p.type = PrimitiveType::kRectangle;
  p.size = Eigen::Vector3d(0, 20, 20);
  p.T_world_primitive = lookAt(point, point + normal);  // local z = normal
  p.T_world_primitive.linear() = p.T_world_primitive.linear() *
                                 Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).matrix();
  EXPECT_TRUE((p.T_world_primitive.linear().col(0) - normal).norm() < 1e-9);
  return p;
}

Renderer makeRenderer(const Scene& scene, bool noise, int threads = 1) {
  Renderer::Params params;
  params.noise = noise;
  params.threads = threads;
  // The independent-noise model: these tests check that the renderer hands the model's noise
  // through; the harsh model's own statistics are tested in test_kinect_depth_model.cpp.
  KinectDepthModel::Params depth = KinectDepthModel::nguyenParams();
  depth.dropout_probability = 0.0;
  return Renderer(buildSurfaces(scene), kCamera, depth, params);
}

Eigen::Vector3d pixelRay(int u, int v) {
  return Eigen::Vector3d((u - kCamera.cx) / kCamera.fx, (v - kCamera.cy) / kCamera.fy, 1.0);
}

}  // namespace

TEST(Renderer, TiltedPlaneDepthMatchesAnalyticDepth) {
  // Camera at the world origin (optical frame = world); plane n.p = d tilted by 30 deg.
  const Eigen::Vector3d n =
      Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitY()) * Eigen::Vector3d(0, 0, -1);
  const Eigen::Vector3d point(0.1, -0.2, 2.0);
  Scene scene;
  scene.primitives.push_back(planeAt(point, n));
  const RenderedFrame frame = makeRenderer(scene, false).render(Eigen::Isometry3d::Identity(), 1);
  const double d = n.dot(point);
  double worst = 0;
  for (int v = 0; v < kCamera.height; v += 3)
    for (int u = 0; u < kCamera.width; u += 3) {
      const double analytic = d / n.dot(pixelRay(u, v));  // depth along the optical axis
      worst = std::max(worst, std::abs(frame.depth.at<float>(v, u) - analytic));
      EXPECT_EQ(frame.labels.at<std::uint16_t>(v, u), 1);
      EXPECT_NEAR(frame.cos_incidence.at<float>(v, u), std::abs(n.dot(pixelRay(u, v).normalized())),
                  1e-5);
    }
  EXPECT_LT(worst, 1e-5);
}

TEST(Renderer, PlaneNoiseHasZeroMeanAndTheModelsStd) {
  // Fronto-parallel plane at 1.5 m, seen from a camera placed anywhere in the world.
  Scene scene;
  const Eigen::Isometry3d T_world_camera =
      lookAt(Eigen::Vector3d(1.0, -2.0, 1.2), Eigen::Vector3d(1.0, 0.0, 1.2));
  const Eigen::Vector3d axis = T_world_camera.linear().col(2);
  scene.primitives.push_back(planeAt(T_world_camera * Eigen::Vector3d(0, 0, 1.5), -axis));
  const Renderer renderer = makeRenderer(scene, true);
  const RenderedFrame frame = renderer.render(T_world_camera, 42);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (int v = 0; v < kCamera.height; ++v)
    for (int u = 0; u < kCamera.width; ++u) {
      const float z = frame.depth.at<float>(v, u);
      ASSERT_NEAR(frame.depth_true.at<float>(v, u), 1.5, 1e-5);
      if (std::isnan(z))
        continue;
      sum += z - 1.5;
      sum2 += (z - 1.5) * (z - 1.5);
      ++n;
    }
  ASSERT_EQ(n, kCamera.width * kCamera.height);
  const double mean = sum / n, std = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 4 * renderer.depthModel().expectedStd(1.5) / std::sqrt(n) + 2e-4);
  EXPECT_NEAR(std / renderer.depthModel().expectedStd(1.5), 1.0, 0.06);
}

TEST(Renderer, SphereDepthAndLabelsMatchAnalyticRaySphereIntersection) {
  const Eigen::Vector3d c(0.1, -0.05, 1.5);
  const double r = 0.2;
  Scene scene;
  scene.primitives.push_back(sphereAt(c, r));
  const RenderedFrame frame = makeRenderer(scene, false).render(Eigen::Isometry3d::Identity(), 1);
  int mismatched = 0, hits = 0;
  for (int v = 0; v < kCamera.height; ++v)
    for (int u = 0; u < kCamera.width; ++u) {
      // |t ray - c|^2 = r^2 with ray = (x, y, 1): t is the depth.
      const Eigen::Vector3d ray = pixelRay(u, v);
      const double a = ray.squaredNorm(), b = -2 * ray.dot(c), cc = c.squaredNorm() - r * r;
      const double disc = b * b - 4 * a * cc;
      const bool hit = disc >= 0;
      const std::uint16_t label = frame.labels.at<std::uint16_t>(v, u);
      if (hit != (label == 1)) {
        ++mismatched;  // only possible on the silhouette, where disc ~ 0
        EXPECT_LT(std::abs(disc), 1e-3);
        continue;
      }
      if (!hit) {
        EXPECT_TRUE(std::isnan(frame.depth.at<float>(v, u)));
        continue;
      }
      ++hits;
      const double t = (-b - std::sqrt(disc)) / (2 * a);
      EXPECT_NEAR(frame.depth.at<float>(v, u), t, 2e-5) << u << " " << v;
    }
  EXPECT_LE(mismatched, 2);
  // Projected disc area: about pi (f r / z)^2 pixels (slightly more off-axis).
  const double expected = M_PI * std::pow(kCamera.fx * r / std::sqrt(c.squaredNorm() - r * r), 2);
  EXPECT_NEAR(hits / expected, 1.0, 0.05);
}

TEST(Renderer, LabelsCarryTheIdsOfTheNearestSurface) {
  // Sphere (id 1) in front of a box whose -z face (id 2 + 5 = 7) faces the camera... order: box
  // faces +x, -x, +y, -y, +z, -z get ids 2..7.
  Scene scene;
  scene.primitives.push_back(sphereAt({0, 0, 1.0}, 0.1));
  PrimitiveSpec box;
  box.name = "box";
  box.type = PrimitiveType::kBox;
  box.size = Eigen::Vector3d(3, 3, 1);
  box.T_world_primitive.translation() = Eigen::Vector3d(0, 0, 3.0);  // -z face at z = 2.5
  scene.primitives.push_back(box);
  const std::vector<Surface> surfaces = buildSurfaces(scene);
  ASSERT_EQ(surfaces.size(), 7u);
  EXPECT_EQ(surfaces[6].name(), "box/-z");
  const RenderedFrame frame = makeRenderer(scene, false).render(Eigen::Isometry3d::Identity(), 1);
  EXPECT_EQ(frame.labels.at<std::uint16_t>(120, 160), 1);   // the sphere, centre of image
  EXPECT_NEAR(frame.depth.at<float>(120, 160), 0.9, 1e-4);  // half a pixel off the centre
  EXPECT_EQ(frame.labels.at<std::uint16_t>(10, 10), 7);     // the box's -z face behind it
  EXPECT_NEAR(frame.depth.at<float>(10, 10), 2.5, 1e-5);
  // With the noise model: label 0 wherever the depth has no data, the id elsewhere.
  const RenderedFrame noisy = makeRenderer(scene, true).render(Eigen::Isometry3d::Identity(), 3);
  int edge_dropouts = 0;
  for (int v = 0; v < kCamera.height; ++v)
    for (int u = 0; u < kCamera.width; ++u) {
      const bool valid = !std::isnan(noisy.depth.at<float>(v, u));
      const std::uint16_t label = noisy.labels.at<std::uint16_t>(v, u);
      EXPECT_EQ(label != 0, valid);
      if (valid) {
        EXPECT_EQ(label, frame.labels.at<std::uint16_t>(v, u));
      } else if (frame.labels.at<std::uint16_t>(v, u) == 7) {
        ++edge_dropouts;  // the box face just outside the sphere's silhouette
      }
    }
  EXPECT_GT(edge_dropouts, 50);
}

TEST(Renderer, ThreadsDoNotChangeTheImage) {
  Scene scene;
  scene.primitives.push_back(sphereAt({0.05, 0.02, 1.2}, 0.3));
  scene.primitives.push_back(planeAt({0, 0, 2.0}, Eigen::Vector3d(0.2, 0, -1).normalized()));
  const Eigen::Isometry3d pose = lookAt({0.1, 0.1, -0.2}, {0, 0, 1.5});
  const RenderedFrame one = makeRenderer(scene, true, 1).render(pose, 5);
  const RenderedFrame three = makeRenderer(scene, true, 3).render(pose, 5);
  cv::Mat a = one.depth.clone(), b = three.depth.clone();
  cv::patchNaNs(a, -1);
  cv::patchNaNs(b, -1);
  EXPECT_EQ(cv::countNonZero(a != b), 0);
  EXPECT_EQ(cv::countNonZero(one.labels != three.labels), 0);
  cv::Mat diff;
  cv::absdiff(one.rgb, three.rgb, diff);
  EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0);
}

TEST(Renderer, ObjectsBehindOrBesideTheCameraAreNotSeen) {
  Scene scene;
  scene.primitives.push_back(sphereAt({0, 0, -1.0}, 0.3));  // behind
  scene.primitives.push_back(sphereAt({3, 0, 0.5}, 0.3));   // far outside the field of view
  scene.primitives.back().name = "side";
  const RenderedFrame frame = makeRenderer(scene, false).render(Eigen::Isometry3d::Identity(), 1);
  EXPECT_EQ(cv::countNonZero(frame.labels), 0);
}
