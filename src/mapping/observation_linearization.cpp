#include "quadric_slam/mapping/observation_linearization.h"

#include <array>
#include <stdexcept>

#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/mapping/factors.h"

namespace quadric_slam {

ObservationLinearization linearizeObservation(const QuadricModel& z_camera,
                                              const Eigen::Isometry3d& T_map_camera,
                                              const QuadricModel& landmark_map) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const QuadricClass c = z_camera.quadricClass();
  if (landmark_map.quadricClass() != c)
    throw std::invalid_argument("linearizeObservation: measurement and landmark classes differ");
  const int k = minimalDimension(c);
  const QuadricObservationCost cost(z_camera, Eigen::MatrixXd::Identity(k, k));
  std::array<double, kPoseParameterSize> pose;
  std::array<double, kQuadricParameterSize> quadric;
  poseToParameters(T_map_camera, pose.data());
  quadricToParameters(landmark_map, quadric.data());
  const double* blocks[2] = {pose.data(), quadric.data()};
  ObservationLinearization out;
  out.residual.resize(k);
  RowMajor J_pose(k, kPoseParameterSize), J_quadric(k, kQuadricParameterSize);
  double* jacobians[2] = {J_pose.data(), J_quadric.data()};
  if (!cost.Evaluate(blocks, out.residual.data(), jacobians))
    return out;
  out.J_camera = J_pose * posePlusJacobian(pose.data());
  const QuadricManifold manifold(c);
  RowMajor plus_q(kQuadricParameterSize, k);
  manifold.PlusJacobian(quadric.data(), plus_q.data());
  out.J_quadric = J_quadric * plus_q;
  out.valid = out.residual.allFinite() && out.J_camera.allFinite() && out.J_quadric.allFinite();
  return out;
}

}  // namespace quadric_slam
