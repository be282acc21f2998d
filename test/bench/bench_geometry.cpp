// Benchmark of the geometry core (not a test): per-call cost of Q decomposition and of the
// observation factor with Jacobians, per class. Built with the package; run
//   .ws/devel/lib/quadric_slam/bench_geometry
#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/mapping/factors.h"

using namespace quadric_slam;

namespace {

Eigen::Isometry3d randomPose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Quaterniond q(u(rng), u(rng), u(rng), u(rng));
  return makeIsometry(q.normalized().toRotationMatrix(),
                      Eigen::Vector3d(u(rng), u(rng), u(rng)) * 2);
}

QuadricModel randomQuadric(QuadricClass c, std::mt19937& rng) {
  switch (c) {
    case QuadricClass::kPlane:
      return QuadricModel(c, randomPose(rng), Eigen::Vector3d::Ones());
    case QuadricClass::kSphere:
      return QuadricModel(c, randomPose(rng), Eigen::Vector3d::Constant(2));
    case QuadricClass::kCylinder:
    case QuadricClass::kCone:
      return QuadricModel(c, randomPose(rng), Eigen::Vector3d(2, 2, 1));
    default:
      return QuadricModel(c, randomPose(rng), Eigen::Vector3d(1, 2, 3), Eigen::Vector4d(1, 1, 1, -1));
  }
}

template <typename F>
double nanosecondsPerCall(int n, F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i)
    f(i);
  const auto t1 = std::chrono::steady_clock::now();
  return std::chrono::duration<double, std::nano>(t1 - t0).count() / n;
}

}  // namespace

int main() {
  std::mt19937 rng(1);
  const int n = 20000;
  std::printf("%-9s %14s %22s %22s\n", "class", "fromMatrix ns", "factor residual ns",
              "factor +jacobians ns");
  for (QuadricClass c : kAllQuadricClasses) {
    std::vector<QuadricModel> quadrics;
    std::vector<Eigen::Matrix4d> matrices;
    for (int i = 0; i < 64; ++i) {
      quadrics.push_back(randomQuadric(c, rng));
      matrices.push_back(quadrics.back().matrix());
    }
    volatile double sink = 0;
    const double t_decompose = nanosecondsPerCall(n, [&](int i) {
      sink = sink + QuadricModel::fromMatrix(matrices[i % 64], c).scale().x();
    });
    const int k = minimalDimension(c);
    std::unique_ptr<ceres::CostFunction> cost(QuadricObservationCost::Create(
        predictMeasurement(randomPose(rng), quadrics[0]), 1e-4 * Eigen::MatrixXd::Identity(k, k)));
    double pose[7], quadric[10];
    poseToParameters(randomPose(rng), pose);
    quadricToParameters(quadrics[1], quadric);
    const double* params[2] = {pose, quadric};
    std::vector<double> r(k), j0(k * 7), j1(k * 10);
    double* jac[2] = {j0.data(), j1.data()};
    const double t_residual = nanosecondsPerCall(n, [&](int) {
      cost->Evaluate(params, r.data(), nullptr);
      sink = sink + r[0];
    });
    const double t_jacobian = nanosecondsPerCall(n, [&](int) {
      cost->Evaluate(params, r.data(), jac);
      sink = sink + j0[0];
    });
    std::printf("%-9s %14.0f %22.0f %22.0f\n", toString(c).c_str(), t_decompose, t_residual,
                t_jacobian);
  }
  return 0;
}
