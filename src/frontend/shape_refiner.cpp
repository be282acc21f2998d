#include "quadric_slam/frontend/shape_refiner.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>

#include "quadric_slam/frontend/levenberg_marquardt.h"
#include "quadric_slam/geometry/quadric_classes.h"

namespace quadric_slam {

void ShapeRefiner::Params::validate() const {
  if (max_iterations < 1 || max_iterations > 100)
    throw std::invalid_argument("ShapeRefiner: max_iterations must be in [1, 100], got " +
                                std::to_string(max_iterations));
  if (!(relative_tolerance > 0 && relative_tolerance < 1))
    throw std::invalid_argument("ShapeRefiner: relative_tolerance must be in (0, 1), got " +
                                std::to_string(relative_tolerance));
  if (!(variance_tolerance >= 0 && variance_tolerance <= 1))
    throw std::invalid_argument("ShapeRefiner: variance_tolerance must be in [0, 1], got " +
                                std::to_string(variance_tolerance));
  if (max_points < 10 || max_points > 10000000)
    throw std::invalid_argument("ShapeRefiner: max_points must be in [10, 1e7], got " +
                                std::to_string(max_points));
}

ShapeRefiner::ShapeRefiner(const Params& params) : params_(params) {
  params_.validate();
}

namespace {

// Whether the shape has a core quadric (finite, radius > 0, cone half angle in (0, pi/2)), which
// the perturbation needs; e.g. a RANSAC cone may come with a half angle beyond pi/2.
bool validShape(const PrimitiveShape& shape) {
  try {
    shape.quadric();
    return true;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

Eigen::VectorXd residuals(const PrimitiveShape& shape, const std::vector<Eigen::Vector3d>& points) {
  Eigen::VectorXd r(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    r[i] = shape.distance(points[i]);
  return r;
}

using Vector9d = Eigen::Matrix<double, 9, 1>;

// Gradient of a general quadric's first-order distance d = f / max(|grad f|, 1e-9)
// (PrimitiveShape::curvedDistance) with respect to its 9 minimal coordinates at zero: the pose
// step (rho, phi) of T exp(xi) (eqs. 9, 16) and the step of the scales (alpha, beta, gamma). In the
// quadric frame the point is x = T^-1 p, which the pose step moves to exp(xi)^-1 x, to first order
// x - rho + x cross phi. With y = S x and signature sigma: f = y^T D(sigma) y + sigma_4 and
// grad f = 2 w in the quadric frame, w = D(sigma) S^2 x; so df/dx = 2 w, df/dS = 2 D(sigma) S x^2,
// d|grad f| = 2 u^T dw with u = w / |w|, dw/dx = D(sigma) S^2, dw/dS = 2 D(sigma) D(S x).
Vector9d generalDistanceGradient(const QuadricModel& q, const Eigen::Vector3d& p) {
  const Eigen::Isometry3d& T = q.pose();
  const Eigen::Vector3d x = T.linear().transpose() * (p - T.translation());
  const Eigen::Vector3d s = q.scale();
  const Eigen::Vector3d sigma = q.signature().head<3>();
  const Eigen::Vector3d sigma_s = sigma.cwiseProduct(s);
  const Eigen::Vector3d w = sigma_s.cwiseProduct(s).cwiseProduct(x);
  const double f = sigma_s.cwiseProduct(s).dot(x.cwiseAbs2()) + q.signature()[3];
  const Eigen::Vector3d df_dx = 2.0 * w;
  const Eigen::Vector3d df_ds = 2.0 * sigma_s.cwiseProduct(x.cwiseAbs2());
  const double w_norm = w.norm();
  const double g = 2.0 * w_norm;
  Eigen::Vector3d dd_dx, dd_ds;
  if (g > 1e-9) {
    const Eigen::Vector3d u = w / w_norm;
    const Eigen::Vector3d dg_dx = 2.0 * sigma_s.cwiseProduct(s).cwiseProduct(u);
    const Eigen::Vector3d dg_ds = 4.0 * sigma_s.cwiseProduct(x).cwiseProduct(u);
    dd_dx = df_dx / g - f * dg_dx / (g * g);
    dd_ds = df_ds / g - f * dg_ds / (g * g);
  } else {  // the floor of the gradient's norm: d = f / 1e-9
    dd_dx = df_dx / 1e-9;
    dd_ds = df_ds / 1e-9;
  }
  Vector9d gradient;
  gradient.head<3>() = -dd_dx;
  gradient.segment<3>(3) = dd_dx.cross(x);
  gradient.tail<3>() = dd_ds;
  return gradient;
}

// d (point, direction, size) / d delta at delta = 0 for the minimal perturbation of a plane,
// sphere, cylinder or cone quadric (QuadricModel::plusMinimal: T exp(xi) with xi = (rho, phi),
// eqs. 9 and 16, and alpha + s on the scale, mapped from the class's Table II coordinates by its
// basis). At zero: d t / d rho = R; the axis R e_c (c = x for a plane's normal, z for an axis)
// moves as d (R e_c) / d phi = -R [e_c]x; a radius 1 / alpha_x moves by -r^2 per unit of alpha_x,
// a cone's half angle atan(1 / alpha_x) by -1 / (1 + alpha_x^2).
using ShapeParameterJacobian = Eigen::Matrix<double, 7, Eigen::Dynamic, 0, 7, 7>;  // on the stack

ShapeParameterJacobian shapeParameterJacobian(const QuadricModel& quadric) {
  const Eigen::Matrix3d R = quadric.pose().linear();
  const QuadricClass c = quadric.quadricClass();
  Eigen::Matrix<double, 7, 9> full = Eigen::Matrix<double, 7, 9>::Zero();
  full.block<3, 3>(0, 0) = R;
  if (c == QuadricClass::kPlane || c == QuadricClass::kCylinder || c == QuadricClass::kCone) {
    const Eigen::Vector3d axis =
        c == QuadricClass::kPlane ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
    Eigen::Matrix3d cross;
    cross << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
    full.block<3, 3>(3, 3) = -R * cross;
  }
  const double alpha = quadric.scale().x();
  if (c == QuadricClass::kSphere || c == QuadricClass::kCylinder)
    full(6, 6) = -1.0 / (alpha * alpha);
  else if (c == QuadricClass::kCone)
    full(6, 6) = -1.0 / (1.0 + alpha * alpha);
  return full * classDefinition(c).basis;
}

// The analytic Jacobian of the distances (not general): row i is base.distanceGradient(p_i)^T D.
// The perturbation acts on the shape's core quadric, whose own (point, direction) may differ from
// the shape's (e.g. a plane's point is the quadric origin offset * normal): base is that quadric's
// shape, where the gradients are taken.
struct DistanceChain {
  PrimitiveShape base;
  ShapeParameterJacobian D;

  explicit DistanceChain(const PrimitiveShape& shape) {
    const QuadricModel quadric = shape.quadric();
    base = PrimitiveShape::fromQuadric(quadric);
    D = shapeParameterJacobian(quadric);
  }
};

// J^T J and J^T r for the distances' Jacobian J (distanceJacobian), accumulated point by point
// without storing J (the refinement needs nothing else).
void normalEquations(const PrimitiveShape& shape, const std::vector<Eigen::Vector3d>& points,
                     const Eigen::VectorXd& r, Eigen::MatrixXd& H, Eigen::VectorXd& g) {
  if (shape.quadric_class == QuadricClass::kGeneral) {
    Eigen::Matrix<double, 9, 9> HH = Eigen::Matrix<double, 9, 9>::Zero();
    Vector9d gg = Vector9d::Zero();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vector9d row = generalDistanceGradient(shape.general_quadric, points[i]);
      HH.noalias() += row * row.transpose();
      gg.noalias() += row * r[static_cast<Eigen::Index>(i)];
    }
    H = HH;
    g = gg;
    return;
  }
  // J = G D with G the per-point gradients in (point, direction, size): accumulate the fixed-size
  // G^T G and G^T r, then H = D^T (G^T G) D and g = D^T (G^T r).
  const DistanceChain chain(shape);
  Eigen::Matrix<double, 7, 7> GG = Eigen::Matrix<double, 7, 7>::Zero();
  Eigen::Matrix<double, 7, 1> Gr = Eigen::Matrix<double, 7, 1>::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Matrix<double, 7, 1> gradient = chain.base.distanceGradient(points[i]);
    GG.noalias() += gradient * gradient.transpose();
    Gr.noalias() += gradient * r[static_cast<Eigen::Index>(i)];
  }
  H = chain.D.transpose() * GG * chain.D;
  g = chain.D.transpose() * Gr;
}

// Covariance of the fit: sigma^2 (J^T J)^-1, J over all points (the sub-sample's normal matrix
// scaled by N / n), sigma^2 the residual variance.
// cost: the sum of the squared distances of points to shape.
ShapeRefiner::Result covarianceOf(const PrimitiveShape& shape,
                                  const std::vector<Eigen::Vector3d>& points, double cost,
                                  std::size_t all_points) {
  ShapeRefiner::Result result;
  const int k = minimalDimension(shape.quadric_class);
  Eigen::MatrixXd H;
  Eigen::VectorXd unused;
  normalEquations(shape, points, Eigen::VectorXd::Zero(points.size()), H, unused);
  H *= static_cast<double>(all_points) / static_cast<double>(points.size());
  const double sigma2 = cost / (static_cast<double>(points.size()) - k);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(H);
  result.shape = shape;
  result.rms = std::sqrt(cost / points.size());
  if (eig.info() != Eigen::Success ||
      eig.eigenvalues().minCoeff() <= 1e-12 * eig.eigenvalues().maxCoeff()) {
    result.covariance = Eigen::MatrixXd::Identity(k, k) * 1e6;
    return result;
  }
  result.covariance = sigma2 * H.inverse();
  result.ok = true;
  return result;
}

}  // namespace

ShapeRefiner::Result ShapeRefiner::refine(const PrimitiveShape& initial,
                                          const std::vector<Eigen::Vector3d>& all_points) const {
  try {
    return refineUnchecked(initial, all_points);
  } catch (const std::invalid_argument&) {  // a shape left its class (no core quadric)
    Result result;
    result.shape = initial;
    return result;
  }
}

ShapeRefiner::Result ShapeRefiner::refineUnchecked(
    const PrimitiveShape& initial, const std::vector<Eigen::Vector3d>& all_points) const {
  Result result;
  result.shape = initial;
  const int k = minimalDimension(initial.quadric_class);
  if (static_cast<int>(all_points.size()) <= k || !validShape(initial))
    return result;

  const std::vector<Eigen::Vector3d> points = evenSubsample(all_points, params_.max_points);

  LevenbergMarquardtSettings settings;
  settings.max_iterations = params_.max_iterations;
  settings.relative_tolerance = params_.relative_tolerance;
  settings.variance_tolerance = params_.variance_tolerance;
  settings.initial_lambda = 1e-4;
  double cost = 0.0;
  const PrimitiveShape shape = minimiseSquares(
      initial, k, settings, [&](const PrimitiveShape& s) { return residuals(s, points); },
      [&](const PrimitiveShape& s, const Eigen::VectorXd& rs, Eigen::MatrixXd& H,
          Eigen::VectorXd& g) { normalEquations(s, points, rs, H, g); },
      [](const PrimitiveShape& s, const Eigen::VectorXd& step) -> std::optional<PrimitiveShape> {
        try {
          return perturb(s, step);
        } catch (const std::invalid_argument&) {  // the step left the class (e.g. negative scale)
          return std::nullopt;
        }
      },
      cost);

  return covarianceOf(shape, points, cost, all_points.size());
}

ShapeRefiner::Result ShapeRefiner::evaluate(const PrimitiveShape& shape,
                                            const std::vector<Eigen::Vector3d>& all_points) const {
  Result result;
  result.shape = shape;
  if (static_cast<int>(all_points.size()) <= minimalDimension(shape.quadric_class) ||
      !validShape(shape))
    return result;
  try {
    const std::vector<Eigen::Vector3d> points = evenSubsample(all_points, params_.max_points);
    return covarianceOf(shape, points, residuals(shape, points).squaredNorm(), all_points.size());
  } catch (const std::invalid_argument&) {
    return result;
  }
}

Eigen::MatrixXd distanceJacobian(const PrimitiveShape& shape,
                                 const std::vector<Eigen::Vector3d>& points) {
  if (shape.quadric_class == QuadricClass::kGeneral) {
    Eigen::MatrixXd J(points.size(), 9);
    for (std::size_t i = 0; i < points.size(); ++i)
      J.row(static_cast<Eigen::Index>(i)) =
          generalDistanceGradient(shape.general_quadric, points[i]).transpose();
    return J;
  }
  // Row by row with D on the stack: no heap temporary per row (and a general matrix product of
  // n x 7 by 7 x k costs more in packing than it saves).
  const DistanceChain chain(shape);
  Eigen::MatrixXd J(points.size(), chain.D.cols());
  for (std::size_t i = 0; i < points.size(); ++i)
    J.row(static_cast<Eigen::Index>(i)).noalias() =
        chain.base.distanceGradient(points[i]).transpose().lazyProduct(chain.D);
  return J;
}

std::vector<Eigen::Vector3d> evenSubsample(const std::vector<Eigen::Vector3d>& all_points,
                                           int max_points) {
  if (static_cast<int>(all_points.size()) <= max_points)
    return all_points;
  std::vector<Eigen::Vector3d> points;
  points.reserve(max_points);
  const double step = static_cast<double>(all_points.size()) / max_points;
  for (int i = 0; i < max_points; ++i)
    points.push_back(all_points[static_cast<std::size_t>(i * step)]);
  return points;
}

PrimitiveShape fitPlane(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points)
    mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const auto& p : points)
    C += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(C);
  Eigen::Vector3d n = eig.eigenvectors().col(0);
  if (n.dot(mean) > 0)
    n = -n;
  PrimitiveShape s = PrimitiveShape::plane(n, n.dot(mean));
  s.point = mean;
  return s;
}

PrimitiveShape fitSphereAlgebraic(const std::vector<Eigen::Vector3d>& points) {
  // |p|^2 + a.p + b = 0 -> centre -a/2, radius sqrt(|a|^2/4 - b).
  Eigen::MatrixXd A(points.size(), 4);
  Eigen::VectorXd y(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    A.row(i) << points[i].x(), points[i].y(), points[i].z(), 1.0;
    y[i] = -points[i].squaredNorm();
  }
  const Eigen::Vector4d x = (A.transpose() * A).ldlt().solve(A.transpose() * y);
  const Eigen::Vector3d centre = -0.5 * x.head<3>();
  const double r2 = centre.squaredNorm() - x[3];
  return PrimitiveShape::sphere(centre, std::sqrt(std::max(r2, 0.0)));
}

double rmsDistance(const PrimitiveShape& shape, const std::vector<Eigen::Vector3d>& points) {
  if (points.empty())
    return 0.0;
  double sum = 0;
  for (const auto& p : points) {
    const double d = shape.distance(p);
    sum += d * d;
  }
  return std::sqrt(sum / points.size());
}

}  // namespace quadric_slam
