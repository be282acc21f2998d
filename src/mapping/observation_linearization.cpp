#include "quadric_slam/mapping/observation_linearization.h"

#include <array>
#include <stdexcept>

#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/mapping/factors.h"

namespace quadric_slam {

ObservationLinearization linearizeObservation(const QuadricModel& z_camera,
                                              const Eigen::Isometry3d& T_map_camera,
                                              const QuadricModel& landmark_map) {
  const QuadricClass c = z_camera.quadricClass();
  if (landmark_map.quadricClass() != c)
    throw std::invalid_argument("linearizeObservation: measurement and landmark classes differ");
  const int k = minimalDimension(c);
  const QuadricObservationCost cost(z_camera,
                                    QuadricObservationCost::MatrixKK::Identity(k, k));
  std::array<double, kPoseParameterSize> pose;
  std::array<double, kQuadricParameterSize> quadric;
  poseToParameters(T_map_camera, pose.data());
  quadricToParameters(landmark_map, quadric.data());
  const double* blocks[2] = {pose.data(), quadric.data()};
  ObservationLinearization out;
  out.residual.resize(k);
  // Straight in the tangent spaces (the same as the cost's ambient Jacobians times the blocks'
  // PlusJacobians, without the round trip through the 7- and 10-parameter blocks).
  QuadricObservationCost::MatrixK9 J_general;
  cost.evaluateTangent(blocks, out.residual.data(), &out.J_camera, &J_general);
  out.J_quadric = J_general.lazyProduct(classDefinition(c).basis);
  out.valid = out.residual.allFinite() && out.J_camera.allFinite() && out.J_quadric.allFinite();
  return out;
}

}  // namespace quadric_slam
