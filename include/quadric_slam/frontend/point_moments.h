// First and second moments of a point set about a fixed reference point: what a plane fit (PCA)
// needs, additive, so that regions, cells and merged regions combine without revisiting points.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace quadric_slam {

struct PointMoments {
  // Points are summed relative to this point (a point of the set): keeps the second moments
  // well conditioned for surfaces metres away.
  Eigen::Vector3d reference = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_sq = Eigen::Matrix3d::Zero();
  double count = 0;

  void add(const Eigen::Vector3d& p) {
    const Eigen::Vector3d q = p - reference;
    sum += q;
    sum_sq += q * q.transpose();
    count += 1;
  }
  // Adds another set's moments (taken about its own reference).
  void add(const PointMoments& other) {
    const Eigen::Vector3d shift = other.reference - reference;
    sum_sq += other.sum_sq + other.sum * shift.transpose() + shift * other.sum.transpose() +
              other.count * shift * shift.transpose();
    sum += other.sum + other.count * shift;
    count += other.count;
  }
  Eigen::Vector3d centroid() const { return sum / count + reference; }
  Eigen::Matrix3d covariance() const {
    const Eigen::Vector3d mean = sum / count;
    return sum_sq / count - mean * mean.transpose();
  }
};

// The PCA plane of a point set: normal (towards the camera at the origin), centroid, the
// eigenvalues of the covariance in increasing order (the first is the mean squared distance to
// the plane) and their eigenvectors (columns; the first is the normal up to sign).
struct MomentPlane {
  Eigen::Vector3d normal, centroid, eigenvalues;
  Eigen::Matrix3d axes;

  explicit MomentPlane(const PointMoments& m) {
    centroid = m.centroid();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m.covariance());
    axes = eig.eigenvectors();
    eigenvalues = eig.eigenvalues().cwiseMax(0.0);
    normal = axes.col(0);
    if (normal.dot(centroid) > 0)
      normal = -normal;
  }
  double offset() const { return normal.dot(centroid); }
  double rms() const { return std::sqrt(eigenvalues[0]); }
};

}  // namespace quadric_slam
