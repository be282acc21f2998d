#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/odometry/point_to_plane_icp.h"
#include "quadric_slam/sim/kinect_depth_model.h"
#include "synthetic_scene.h"

namespace quadric_slam {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Isometry3d motion(const Eigen::Vector3d& t, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = t;
  return T;
}

double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.inverse() * b).translation().norm();
}
double rotationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return pose_math::rotationAngle(a.inverse() * b);
}

void expectRejected(void (*mutate)(PointToPlaneIcp::Params&), const std::string& field) {
  PointToPlaneIcp::Params p;
  mutate(p);
  try {
    p.validate();
    ADD_FAILURE() << "validate() accepted a bad " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(PointToPlaneIcp, ParamsValidateNamesTheBadField) {
  EXPECT_NO_THROW(PointToPlaneIcp::Params().validate());
  expectRejected([](PointToPlaneIcp::Params& p) { p.pyramid_levels = 0; }, "pyramid_levels");
  expectRejected([](PointToPlaneIcp::Params& p) { p.finest_stride = 64; }, "finest_stride");
  expectRejected([](PointToPlaneIcp::Params& p) { p.reference_stride = 0; }, "reference_stride");
  expectRejected([](PointToPlaneIcp::Params& p) { p.max_iterations = 0; }, "max_iterations");
  expectRejected([](PointToPlaneIcp::Params& p) { p.max_correspondence_distance = -1; },
                 "max_correspondence_distance");
  expectRejected([](PointToPlaneIcp::Params& p) { p.coarse_distance_factor = 0.5; },
                 "coarse_distance_factor");
  expectRejected([](PointToPlaneIcp::Params& p) { p.max_normal_angle = 4; }, "max_normal_angle");
  expectRejected([](PointToPlaneIcp::Params& p) { p.huber_delta = 0; }, "huber_delta");
  expectRejected([](PointToPlaneIcp::Params& p) { p.convergence_translation = 0; },
                 "convergence_translation");
  expectRejected([](PointToPlaneIcp::Params& p) { p.convergence_rotation = -1; },
                 "convergence_rotation");
  expectRejected([](PointToPlaneIcp::Params& p) { p.min_correspondences = 5; },
                 "min_correspondences");
  expectRejected([](PointToPlaneIcp::Params& p) { p.min_eigenvalue_ratio = 1; },
                 "min_eigenvalue_ratio");
  expectRejected([](PointToPlaneIcp::Params& p) { p.degenerate_variance = 0; },
                 "degenerate_variance");
  expectRejected(
      [](PointToPlaneIcp::Params& p) {
        p.max_translation_from_guess = std::numeric_limits<double>::quiet_NaN();
      },
      "max_translation_from_guess");
  expectRejected([](PointToPlaneIcp::Params& p) { p.max_rotation_from_guess = 0; },
                 "max_rotation_from_guess");
  PointToPlaneIcp::Params bad;
  bad.huber_delta = -1;
  EXPECT_THROW(PointToPlaneIcp icp(bad), std::invalid_argument);
}

TEST(PointToPlaneIcp, DecimationFollowsCloudWidth) {
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  std::string why;
  EXPECT_EQ(organizedCloudDecimation(k, 640, 480, &why), 1);
  EXPECT_EQ(organizedCloudDecimation(k, 320, 240, &why), 2);
  EXPECT_EQ(organizedCloudDecimation(k, 213, 160, &why), 3);
  EXPECT_EQ(organizedCloudDecimation(k, 320, 200, &why), 0);
  EXPECT_NE(why.find("320 x 200"), std::string::npos) << why;
  EXPECT_EQ(organizedCloudDecimation(k, 640 * 480, 1, &why), 0);
  EXPECT_EQ(organizedCloudDecimation(CameraIntrinsics(), 640, 480, &why), 0);
  EXPECT_NE(why.find("intrinsics"), std::string::npos) << why;
}

class IcpOnRoom : public ::testing::Test {
 protected:
  const synthetic::Scene scene_ = synthetic::roomScene();
  const CameraIntrinsics k_ = synthetic::vgaIntrinsics();
  const Eigen::Isometry3d T_world_a_ =
      synthetic::lookAt(Eigen::Vector3d(-0.3, -0.3, 1.5), Eigen::Vector3d(2.0, 2.0, 0.7));
};

// A known motion of 3 cm and about 2 degrees between two noisy VGA frames is recovered to 1 mm and
// 0.1 degree from an identity initial guess.
TEST_F(IcpOnRoom, RecoversKnownRigidMotion) {
  const Eigen::Isometry3d T_a_b =
      motion(Eigen::Vector3d(0.02, -0.01, 0.02), Eigen::Vector3d(1.0, -1.5, 0.8) * kDeg);
  // Kinect-like depth noise: 1.5 mm at 1 m, 6 mm at 2 m.
  const double noise = 0.0015;
  auto a = synthetic::renderCloud(scene_, T_world_a_, k_, 1, noise, 11);
  auto b = synthetic::renderCloud(scene_, T_world_a_ * T_a_b, k_, 1, noise, 12);

  // Every second point at the finest level (the default samples every fourth, for speed: its
  // errors on this scene are 0.2-0.9 mm over five noise seeds).
  PointToPlaneIcp::Params params;
  params.finest_stride = 2;
  PointToPlaneIcp icp(params);
  icp.setReference(*a, k_);
  const PointToPlaneIcp::Result r = icp.align(*b, Eigen::Isometry3d::Identity());
  ASSERT_EQ(r.status, TrackingStatus::kOk) << r.message;
  EXPECT_EQ(r.constrained_dof, 6);
  EXPECT_LT(translationError(r.T_reference_current, T_a_b), 1e-3);
  EXPECT_LT(rotationError(r.T_reference_current, T_a_b), 0.1 * kDeg);
  EXPECT_GT(r.inlier_fraction, 0.8);
  EXPECT_GT(r.correspondences, 10000);
  // Residuals normalised to 1 m depth: two noisy points of 1.5 mm each give about 2 mm.
  EXPECT_LT(r.rms_residual, 0.004);
  EXPECT_GT(r.rms_residual, 0.001);
  // Covariance: symmetric positive definite with sub-millimetre standard deviations, and the
  // actual error within four of them.
  EXPECT_TRUE(r.covariance.isApprox(r.covariance.transpose()));
  Eigen::SelfAdjointEigenSolver<Matrix6d> eig(r.covariance);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  EXPECT_LT(std::sqrt(r.covariance.diagonal().head<3>().maxCoeff()), 1e-3);
  const Eigen::Vector3d position_error = r.T_reference_current.translation() - T_a_b.translation();
  for (int i = 0; i < 3; ++i)
    EXPECT_LT(std::abs(position_error(i)), 4 * std::sqrt(r.covariance(i, i))) << "axis " << i;
}

// The same with a decimated (320 x 240) cloud: intrinsics are scaled from the cloud width.
TEST_F(IcpOnRoom, RecoversMotionOnDecimatedClouds) {
  const Eigen::Isometry3d T_a_b =
      motion(Eigen::Vector3d(-0.015, 0.01, 0.03), Eigen::Vector3d(-0.5, 1.0, -1.2) * kDeg);
  auto a = synthetic::renderCloud(scene_, T_world_a_, k_, 2, 0.0015, 21);
  auto b = synthetic::renderCloud(scene_, T_world_a_ * T_a_b, k_, 2, 0.0015, 22);
  PointToPlaneIcp::Params params;
  params.finest_stride = 2;
  params.reference_stride = 1;
  PointToPlaneIcp icp(params);
  icp.setReference(*a, k_);
  const PointToPlaneIcp::Result r = icp.align(*b, Eigen::Isometry3d::Identity());
  ASSERT_EQ(r.status, TrackingStatus::kOk) << r.message;
  EXPECT_LT(translationError(r.T_reference_current, T_a_b), 1e-3);
  EXPECT_LT(rotationError(r.T_reference_current, T_a_b), 0.1 * kDeg);
}

// A result further from the prior than max_translation_from_guess is refused as implausible: the
// status is lost and the prior comes back (here the true 3 cm motion exceeds a 1 cm limit).
TEST_F(IcpOnRoom, ImplausibleJumpFromPriorIsLost) {
  const Eigen::Isometry3d T_a_b = motion(Eigen::Vector3d(0.03, 0, 0), Eigen::Vector3d::Zero());
  auto a = synthetic::renderCloud(scene_, T_world_a_, k_, 4);
  auto b = synthetic::renderCloud(scene_, T_world_a_ * T_a_b, k_, 4);
  PointToPlaneIcp::Params params;
  params.finest_stride = 1;
  params.reference_stride = 1;
  params.max_translation_from_guess = 0.01;
  PointToPlaneIcp icp(params);
  icp.setReference(*a, k_);
  const PointToPlaneIcp::Result r = icp.align(*b, Eigen::Isometry3d::Identity());
  EXPECT_EQ(r.status, TrackingStatus::kLost);
  EXPECT_NE(r.message.find("implausible"), std::string::npos) << r.message;
  EXPECT_TRUE(r.T_reference_current.isApprox(Eigen::Isometry3d::Identity()));
  // With the default limit (0.3 m) the same alignment is accepted.
  PointToPlaneIcp::Params loose = params;
  loose.max_translation_from_guess = 0.3;
  PointToPlaneIcp icp_loose(loose);
  icp_loose.setReference(*a, k_);
  const PointToPlaneIcp::Result ok = icp_loose.align(*b, Eigen::Isometry3d::Identity());
  EXPECT_EQ(ok.status, TrackingStatus::kOk) << ok.message;
  EXPECT_LT(translationError(ok.T_reference_current, T_a_b), 1e-3);
}

// A wrong intrinsics/cloud pairing is refused, not silently used.
TEST_F(IcpOnRoom, RejectsReferenceOfWrongSize) {
  auto a = synthetic::renderCloud(scene_, T_world_a_, k_, 2);
  CameraIntrinsics other = k_;
  other.height = 400;
  PointToPlaneIcp icp(PointToPlaneIcp::Params{});
  EXPECT_THROW(icp.setReference(*a, other), std::invalid_argument);
}

// A single plane constrains only its normal distance and two tilts: the status is degenerate, the
// constrained directions are still right, and the unconstrained ones stay at the prior.
TEST(PointToPlaneIcpDegenerate, SinglePlaneKeepsPriorInFreeDirections) {
  synthetic::Scene wall;
  wall.planes.push_back({Eigen::Vector3d(0, 1, 0), 2.0});  // the plane y = 2 (world)
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  const Eigen::Isometry3d T_world_a =
      synthetic::lookAt(Eigen::Vector3d(0, 0, 1.0), Eigen::Vector3d(0, 2.0, 1.0));
  // The camera looks along world +y: camera z = world y. Move 2 cm towards the wall, 5 cm
  // sideways (unobservable) and turn 1 degree about the optical axis (unobservable).
  const Eigen::Isometry3d T_a_b =
      motion(Eigen::Vector3d(0.05, 0.0, 0.02), Eigen::Vector3d(0, 0, 1.0) * kDeg);
  auto a = synthetic::renderCloud(wall, T_world_a, k, 2, 0.0015, 31);
  auto b = synthetic::renderCloud(wall, T_world_a * T_a_b, k, 2, 0.0015, 32);
  PointToPlaneIcp::Params params;
  params.finest_stride = 2;
  params.reference_stride = 1;
  PointToPlaneIcp icp(params);
  icp.setReference(*a, k);
  const PointToPlaneIcp::Result r = icp.align(*b, Eigen::Isometry3d::Identity());
  ASSERT_EQ(r.status, TrackingStatus::kDegenerate) << r.message;
  EXPECT_EQ(r.constrained_dof, 3);
  EXPECT_NE(r.message.find("degenerate"), std::string::npos);
  const Eigen::Isometry3d& T = r.T_reference_current;
  // Constrained: the distance to the wall (camera z) and the tilts about camera x and y.
  EXPECT_NEAR(T.translation().z(), 0.02, 1e-3);
  const Eigen::Vector3d z_axis = T.linear().col(2);
  EXPECT_NEAR(z_axis.x(), 0.0, 1e-3);
  EXPECT_NEAR(z_axis.y(), 0.0, 1e-3);
  // Unconstrained: kept at the prior (identity), so the pose stays bounded.
  EXPECT_LT(std::abs(T.translation().x()), 5e-3);
  EXPECT_LT(std::abs(T.translation().y()), 5e-3);
  EXPECT_LT(pose_math::rotationAngle(T), 0.2 * kDeg);
  // The covariance says which directions are unknown.
  EXPECT_GE(r.covariance(0, 0), params.degenerate_variance * 0.5);
  EXPECT_LT(r.covariance(2, 2), 1e-4);
}

// Organized cloud with normals of the scene seen from T_world_camera through the harsh Kinect v1
// depth model (sim/kinect_depth_model.h: noise growing with z^2, correlated over neighbouring
// pixels, disparity quantisation, the fixed radial distortion). The scene's planes only.
pcl::PointCloud<pcl::PointNormal>::Ptr kinectCloud(const synthetic::Scene& scene,
                                                   const Eigen::Isometry3d& T_world_camera,
                                                   const CameraIntrinsics& k, unsigned seed) {
  const pcl::PointCloud<pcl::PointXYZ> exact =
      synthetic::renderDepth(scene, T_world_camera, k, 1, 0.0, seed);
  cv::Mat depth(k.height, k.width, CV_32FC1), cos_incidence(k.height, k.width, CV_32FC1);
  const Eigen::Vector3d normal_camera =
      T_world_camera.linear().transpose() * scene.planes.front().normal;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      depth.at<float>(v, u) = exact(u, v).z;
      const Eigen::Vector3d ray =
          Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0).normalized();
      cos_incidence.at<float>(v, u) = static_cast<float>(std::abs(ray.dot(normal_camera)));
    }
  }
  const cv::Mat noisy = KinectDepthModel().apply(depth, cos_incidence, seed);
  pcl::PointCloud<pcl::PointXYZ> cloud(k.width, k.height);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const float z = noisy.at<float>(v, u);
      cloud(u, v) = pcl::PointXYZ(static_cast<float>((u - k.cx) * z / k.fx),
                                  static_cast<float>((v - k.cy) * z / k.fy), z);
    }
  }
  static const NormalEstimator estimator{NormalEstimator::Params()};
  return pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>(estimator.compute(cloud));
}

// A single wall 4 m away, seen through the Kinect v1 model: its normals tilt by 15-25 degrees,
// which makes H look constrained along the wall, but the data cannot say where the camera is along
// it. Judged by the eigenvalue ratio alone the status is ok and the pose along the wall is wherever
// the noise puts it; judged against the normals' noise (noise_information_factor) the status is
// degenerate and the directions along the wall keep the prior.
TEST(PointToPlaneIcpDegenerate, AFarNoisyWallDoesNotHoldThePoseAlongItself) {
  synthetic::Scene wall;
  wall.planes.push_back({Eigen::Vector3d(0, 1, 0), 4.0});  // the plane y = 4 (world)
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  const Eigen::Isometry3d T_world_a =
      synthetic::lookAt(Eigen::Vector3d(0, 0, 1.0), Eigen::Vector3d(0, 4.0, 1.0));
  // 1 cm towards the wall (camera z), 1 cm sideways (camera x, unobservable).
  const Eigen::Isometry3d T_a_b = motion(Eigen::Vector3d(0.01, 0.0, 0.01), Eigen::Vector3d::Zero());
  auto a = kinectCloud(wall, T_world_a, k, 41);
  auto b = kinectCloud(wall, T_world_a * T_a_b, k, 42);
  PointToPlaneIcp::Params params;
  params.min_eigenvalue_ratio = 2e-3;  // config/odometry.yaml
  params.noise_information_factor = 0.0;
  PointToPlaneIcp ratio_only(params);
  ratio_only.setReference(*a, k);
  const PointToPlaneIcp::Result fooled = ratio_only.align(*b, Eigen::Isometry3d::Identity());
  EXPECT_EQ(fooled.status, TrackingStatus::kOk) << fooled.message;
  EXPECT_LT(fooled.information_over_noise, 4.0);  // the noise explains most of H's information

  params.noise_information_factor = PointToPlaneIcp::Params().noise_information_factor;
  ASSERT_GT(params.noise_information_factor, 0.0);
  PointToPlaneIcp judged(params);
  judged.setReference(*a, k);
  const PointToPlaneIcp::Result r = judged.align(*b, Eigen::Isometry3d::Identity());
  ASSERT_EQ(r.status, TrackingStatus::kDegenerate) << r.message;
  EXPECT_LE(r.constrained_dof, 4);
  const Eigen::Isometry3d& T = r.T_reference_current;
  // Constrained: the distance to the wall.
  EXPECT_NEAR(T.translation().z(), 0.01, 5e-3);
  // Along the wall: near the prior (identity; the tilts, measured about the camera, move it a few
  // millimetres), not a noise-driven slide.
  EXPECT_LT(std::abs(T.translation().x()), 5e-3);
  EXPECT_LT(std::abs(T.translation().y()), 5e-3);
  EXPECT_GE(r.covariance(0, 0), params.degenerate_variance * 0.5);
}

TEST(PointToPlaneIcpLost, EmptyOrUnusableCloudsGiveLost) {
  const synthetic::Scene scene = synthetic::roomScene();
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  const Eigen::Isometry3d T_world_a =
      synthetic::lookAt(Eigen::Vector3d(-0.3, -0.3, 1.5), Eigen::Vector3d(2.0, 2.0, 0.7));
  auto a = synthetic::renderCloud(scene, T_world_a, k, 4);
  PointToPlaneIcp icp(PointToPlaneIcp::Params{});
  const Eigen::Isometry3d guess =
      motion(Eigen::Vector3d(0.01, 0.02, 0.03), Eigen::Vector3d::Zero());

  // No reference yet.
  PointToPlaneIcp::Result r = icp.align(*a, guess);
  EXPECT_EQ(r.status, TrackingStatus::kLost);
  EXPECT_TRUE(r.T_reference_current.isApprox(guess));

  icp.setReference(*a, k);
  pcl::PointCloud<pcl::PointNormal> empty;
  r = icp.align(empty, guess);
  EXPECT_EQ(r.status, TrackingStatus::kLost);
  EXPECT_TRUE(r.T_reference_current.isApprox(guess));
  EXPECT_FALSE(r.message.empty());

  // All NaN (no depth at all).
  pcl::PointCloud<pcl::PointNormal> blank(160, 120);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (auto& p : blank.points) {
    p.x = p.y = p.z = p.normal_x = p.normal_y = p.normal_z = p.curvature = nan;
  }
  r = icp.align(blank, guess);
  EXPECT_EQ(r.status, TrackingStatus::kLost);
  EXPECT_EQ(r.candidate_points, 0);
  EXPECT_NE(r.message.find("too few"), std::string::npos) << r.message;

  // Only a handful of valid points.
  pcl::PointCloud<pcl::PointNormal> sparse = blank;
  for (int i = 0; i < 20; ++i)
    sparse(80, 60 + i) = (*a)(80, 60 + i);
  r = icp.align(sparse, guess);
  EXPECT_EQ(r.status, TrackingStatus::kLost);
  EXPECT_TRUE(r.T_reference_current.isApprox(guess));

  // Unorganized.
  pcl::PointCloud<pcl::PointNormal> flat;
  flat.points = a->points;
  flat.width = static_cast<std::uint32_t>(a->size());
  flat.height = 1;
  r = icp.align(flat, guess);
  EXPECT_EQ(r.status, TrackingStatus::kLost);
}

// A frame of an unrelated scene (a few balls 0.8-1.2 m away, nothing behind them) is not forced
// onto the reference (walls 2-4 m away): it is lost and the guess is returned. (The opposite
// corner of the room would not do: the bare room is symmetric, so walls align with walls.)
TEST(PointToPlaneIcpLost, UnrelatedFrameIsNotAccepted) {
  const CameraIntrinsics k = synthetic::vgaIntrinsics();
  const Eigen::Isometry3d T_world_camera =
      synthetic::lookAt(Eigen::Vector3d(-0.3, -0.3, 1.5), Eigen::Vector3d(2, 2, 0.7));
  auto a = synthetic::renderCloud(synthetic::roomScene(), T_world_camera, k, 4);
  synthetic::Scene balls;
  for (int i = 0; i < 3; ++i) {
    balls.spheres.push_back(
        {T_world_camera * Eigen::Vector3d(-0.3 + 0.3 * i, 0.1 * (i - 1), 0.8 + 0.2 * i), 0.15});
  }
  auto b = synthetic::renderCloud(balls, T_world_camera, k, 4);
  PointToPlaneIcp::Params params;
  params.finest_stride = 1;
  params.reference_stride = 1;
  PointToPlaneIcp icp(params);
  icp.setReference(*a, k);
  ASSERT_GT(icp.usablePoints(*b), params.min_correspondences);  // enough points, wrong ones
  const PointToPlaneIcp::Result r = icp.align(*b, Eigen::Isometry3d::Identity());
  EXPECT_EQ(r.status, TrackingStatus::kLost) << r.message;
  EXPECT_TRUE(r.T_reference_current.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_LT(r.correspondences, params.min_correspondences);
}

}  // namespace
}  // namespace quadric_slam
