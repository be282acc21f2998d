#include "quadric_slam/geometry/quadric.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "quadric_slam/geometry/quadric_classes.h"

namespace quadric_slam {

namespace {

std::string vecString(const Eigen::VectorXd& v) {
  std::ostringstream os;
  os << "(" << v.transpose() << ")";
  return os.str();
}

void checkScaleTies(QuadricClass c, const Eigen::Vector3d& scale, double tol) {
  const Eigen::Vector3d constrained = constrainScale(c, scale);
  if ((constrained - scale).cwiseAbs().maxCoeff() >
      tol * std::max(1.0, scale.cwiseAbs().maxCoeff()))
    throw std::invalid_argument("QuadricModel: scale " + vecString(scale) + " violates the " +
                                toString(c) + " class constraint, expected " +
                                vecString(constrained));
}

}  // namespace

QuadricModel::QuadricModel() = default;

QuadricModel::QuadricModel(QuadricClass quadric_class, const Eigen::Isometry3d& T_frame_quadric,
                           const Eigen::Vector3d& scale)
    : QuadricModel(quadric_class, T_frame_quadric, scale, defaultSignature(quadric_class)) {}

QuadricModel::QuadricModel(QuadricClass quadric_class, const Eigen::Isometry3d& T_frame_quadric,
                           const Eigen::Vector3d& scale, const Eigen::Vector4d& signature)
    : class_(quadric_class),
      T_frame_quadric_(T_frame_quadric),
      scale_(scale),
      signature_(signature) {
  classDefinition(quadric_class);  // validates the enum value
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(scale[i]) || scale[i] <= 0)
      throw std::invalid_argument("QuadricModel: scale " + vecString(scale) +
                                  " must be finite and > 0 in every entry");
  }
  for (int i = 0; i < 4; ++i) {
    if (signature[i] != 1 && signature[i] != -1 && signature[i] != 0)
      throw std::invalid_argument("QuadricModel: signature " + vecString(signature) +
                                  " must have entries in {+1, -1, 0}");
  }
  if (!T_frame_quadric.matrix().allFinite())
    throw std::invalid_argument("QuadricModel: pose is not finite");
  if (quadric_class != QuadricClass::kGeneral) {
    if (signature != defaultSignature(quadric_class))
      throw std::invalid_argument("QuadricModel: a " + toString(quadric_class) + " has signature " +
                                  vecString(defaultSignature(quadric_class)) + ", got " +
                                  vecString(signature));
    checkScaleTies(quadric_class, scale, 1e-6);
  } else if (signature.head<3>().cwiseAbs().sum() == 0) {
    throw std::invalid_argument("QuadricModel: signature " + vecString(signature) +
                                " has no quadratic part");
  }
}

// eqs. 4-5
Eigen::Matrix4d QuadricModel::matrix() const {
  Eigen::Matrix4d S_h = Eigen::Matrix4d::Identity();
  S_h.diagonal().head<3>() = scale_;
  const Eigen::Matrix4d T = T_frame_quadric_.inverse().matrix();
  return T.transpose() * S_h.transpose() * signature_.asDiagonal() * S_h * T;
}

QuadricModel QuadricModel::fromMatrix(const Eigen::Matrix4d& Q_in, QuadricClass quadric_class,
                                      double relative_tolerance) {
  classDefinition(quadric_class);
  if (!Q_in.allFinite())
    throw std::invalid_argument("QuadricModel::fromMatrix: Q is not finite");
  const double norm = Q_in.cwiseAbs().maxCoeff();
  if (norm == 0)
    throw std::invalid_argument("QuadricModel::fromMatrix: Q is zero");
  const Eigen::Matrix4d Q = Q_in / norm;
  if ((Q - Q.transpose()).cwiseAbs().maxCoeff() > 1e-9)
    throw std::invalid_argument("QuadricModel::fromMatrix: Q is not symmetric");
  const double tol = 1e-9;  // rank tolerance on the normalised Q

  const Eigen::Matrix3d A = Q.topLeftCorner<3, 3>();
  const Eigen::Vector3d b = Q.topRightCorner<3, 1>();
  const double c = Q(3, 3);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(A);
  Eigen::Vector3d lambda = eig.eigenvalues();
  const Eigen::Matrix3d V = eig.eigenvectors();
  const double lambda_max = lambda.cwiseAbs().maxCoeff();
  if (lambda_max <= tol)
    throw std::invalid_argument(
        "QuadricModel::fromMatrix: Q has no quadratic part (a single plane in linear form is not a "
        "supported quadric; planes use the double-plane form (alpha x)^2 = 0)");
  const double rank_tol = std::max(tol, relative_tolerance * 1e-3 * lambda_max);
  int rank = 0;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(lambda[i]) > rank_tol)
      ++rank;
    else
      lambda[i] = 0;
  }

  if (rank == 1) {
    // Double plane: Q = lambda [n; -d][n; -d]^T, rank 1.
    int i_max = 0;
    lambda.cwiseAbs().maxCoeff(&i_max);
    const Eigen::Vector3d n = V.col(i_max);
    const double l = lambda[i_max];
    const double beta = n.dot(b);
    if ((b - beta * n).norm() > 1e3 * tol || std::abs(c - beta * beta / l) > 1e3 * tol)
      throw std::invalid_argument(
          "QuadricModel::fromMatrix: rank-1 quadratic part but Q is not a double plane (parabolic "
          "cylinder or pair of parallel planes: not supported)");
    if (quadric_class != QuadricClass::kPlane)
      throw std::invalid_argument("QuadricModel::fromMatrix: Q is a plane, requested class " +
                                  toString(quadric_class));
    const double d = -beta / l;  // n.p = d
    Eigen::Matrix3d R;
    R.col(0) = n;
    R.col(1) = n.unitOrthogonal();
    R.col(2) = n.cross(R.col(1));
    return QuadricModel(QuadricClass::kPlane, makeIsometry(R, d * n), Eigen::Vector3d::Ones());
  }
  if (quadric_class == QuadricClass::kPlane)
    throw std::invalid_argument("QuadricModel::fromMatrix: requested a plane, but Q has rank-" +
                                std::to_string(rank) + " quadratic part");

  // Centre: A t = -b on the range of A; b must lie in that range (no paraboloids).
  Eigen::Matrix3d A_pinv = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (lambda[i] != 0)
      A_pinv += V.col(i) * V.col(i).transpose() / lambda[i];
  }
  for (int i = 0; i < 3; ++i) {
    if (lambda[i] == 0 && std::abs(V.col(i).dot(b)) > 1e3 * rank_tol)
      throw std::invalid_argument(
          "QuadricModel::fromMatrix: the linear part is not in the range of the quadratic part "
          "(paraboloid or parabolic cylinder): not supported");
  }
  const Eigen::Vector3d t = -A_pinv * b;
  double k = c + b.dot(t);  // value of the polynomial at the centre
  if (std::abs(k) <= rank_tol)
    k = 0;
  if (k == 0 && rank == 2)
    throw std::invalid_argument(
        "QuadricModel::fromMatrix: degenerate Q (pair of intersecting planes or a line)");

  // Sylvester's law of inertia: the sign pattern of (lambda, k) up to the overall sign.
  int pos = 0, neg = 0;
  for (int i = 0; i < 3; ++i) {
    pos += lambda[i] > 0;
    neg += lambda[i] < 0;
  }
  double overall = 1.0;
  if (neg > pos || (neg == pos && k > 0))
    overall = -1.0;
  lambda *= overall;
  k *= overall;
  if (overall < 0)
    std::swap(pos, neg);
  if (neg == 0 && k > 0)
    throw std::invalid_argument(
        "QuadricModel::fromMatrix: Q has no real points (imaginary quadric)");
  if (neg == 0 && k == 0)
    throw std::invalid_argument("QuadricModel::fromMatrix: degenerate Q (a single point)");

  // Order the axes: +1 first, then -1, then 0.
  std::vector<int> order = {0, 1, 2};
  auto group = [&](int i) { return lambda[i] > 0 ? 0 : (lambda[i] < 0 ? 1 : 2); };
  std::stable_sort(order.begin(), order.end(), [&](int a, int b2) { return group(a) < group(b2); });
  // Normalisation: |sigma4| = 1, or for a cone the (single) -1 axis gets scale 1.
  double unit = std::abs(k);
  if (k == 0) {
    if (neg != 1)
      throw std::invalid_argument("QuadricModel::fromMatrix: unsupported cone signature");
    unit = std::abs(lambda[order[2]]);
  }
  Eigen::Matrix3d R;
  Eigen::Vector3d scale;
  Eigen::Vector4d sigma;
  for (int j = 0; j < 3; ++j) {
    const int i = order[j];
    R.col(j) = V.col(i);
    sigma[j] = group(i) == 0 ? 1 : (group(i) == 1 ? -1 : 0);
    scale[j] = lambda[i] == 0 ? 1.0 : std::sqrt(std::abs(lambda[i]) / unit);
  }
  sigma[3] = k > 0 ? 1 : (k < 0 ? -1 : 0);
  if (R.determinant() < 0)
    R.col(2) = -R.col(2);  // flipping an axis leaves D(sigma) unchanged

  if (quadric_class != QuadricClass::kGeneral) {
    if (sigma != defaultSignature(quadric_class))
      throw std::invalid_argument("QuadricModel::fromMatrix: Q has signature " + vecString(sigma) +
                                  ", not that of a " + toString(quadric_class) + " " +
                                  vecString(defaultSignature(quadric_class)));
    checkScaleTies(quadric_class, scale, relative_tolerance);
    scale = constrainScale(quadric_class, scale);
  }
  return QuadricModel(quadric_class, makeIsometry(R, t), scale, sigma);
}

QuadricModel QuadricModel::transformed(const Eigen::Isometry3d& T_A_frame) const {
  QuadricModel out = *this;
  out.T_frame_quadric_ = T_A_frame * T_frame_quadric_;
  return out;
}

// eqs. 9, 11 (body frame), 16
QuadricModel QuadricModel::plus(const Vector9d& delta) const {
  QuadricModel out = *this;
  out.T_frame_quadric_ = quadric_slam::plus(T_frame_quadric_, delta.head<6>());
  for (int i = 0; i < 3; ++i)
    out.scale_(i) = stepScale(scale_(i), delta(6 + i));
  return out;
}

// eqs. 10, 14, 17
Vector9d QuadricModel::minus(const QuadricModel& other) const {
  Vector9d d;
  d.head<6>() = quadric_slam::minus(T_frame_quadric_, other.T_frame_quadric_);
  d.tail<3>() = scale_ - other.scale_;
  return d;
}

QuadricModel QuadricModel::plusMinimal(const Eigen::VectorXd& delta) const {
  const QuadricClassDefinition& def = classDefinition(class_);
  if (delta.size() != def.minimal_dimension)
    throw std::invalid_argument("QuadricModel::plusMinimal: a " + toString(class_) + " takes " +
                                std::to_string(def.minimal_dimension) + " parameters, got " +
                                std::to_string(delta.size()));
  return plus(def.basis * delta);
}

Eigen::VectorXd QuadricModel::minusMinimal(const QuadricModel& other) const {
  return basisPseudoInverse(class_) * minus(other);
}

// eq. 19
QuadricModel predictMeasurement(const Eigen::Isometry3d& T_world_camera,
                                const QuadricModel& quadric_world) {
  return quadric_world.transformed(T_world_camera.inverse());
}

}  // namespace quadric_slam
