#include "quadric_slam/mapping/measurement_model_error.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/geometry/symmetry.h"

namespace quadric_slam {

namespace {

void requireRange(bool ok, const char* field, const char* range) {
  if (!ok)
    throw std::invalid_argument(std::string("MeasurementModelError::Params::") + field +
                                " must be in " + range);
}

}  // namespace

void MeasurementModelError::Params::validate() const {
  requireRange(std::isfinite(sigma) && sigma >= 0.0 && sigma <= 0.1, "sigma", "[0, 0.1] m");
  requireRange(
      std::isfinite(correlation_angle) && correlation_angle > 0.0 && correlation_angle <= 1.5,
      "correlation_angle", "(0, 1.5] rad");
}

double MeasurementModelError::supportDepth(const QuadricMeasurement& measurement) {
  const Eigen::Vector3d centre = 0.5 * (measurement.extent_min + measurement.extent_max);
  const double z = (measurement.quadric_camera.pose() * centre).z();
  return std::isfinite(z) ? std::max(z, 0.1) : 0.1;
}

double MeasurementModelError::independentCells(const QuadricMeasurement& measurement,
                                               const Params& params) {
  Eigen::Vector3d sides = (measurement.extent_max - measurement.extent_min).cwiseAbs();
  if (!sides.allFinite())
    return 1.0;
  std::sort(sides.data(), sides.data() + 3, std::greater<double>());
  const double cell = params.correlation_angle * supportDepth(measurement);
  const double cells = sides[0] * sides[1] / (cell * cell);
  return std::clamp(cells, 1.0, std::max(1.0, static_cast<double>(measurement.num_points)));
}

Eigen::MatrixXd MeasurementModelError::covariance(const QuadricMeasurement& measurement,
                                                  const Params& params) {
  const int k = minimalDimension(measurement.quadric_camera.quadricClass());
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(k, k);
  const Eigen::MatrixXd& fit = measurement.covariance;
  const double rms = measurement.fit_rms;
  if (measurement.quadric_camera.quadricClass() == QuadricClass::kGeneral || params.sigma == 0.0 ||
      fit.rows() != k || fit.cols() != k || !fit.allFinite() || !(rms > 0.0) ||
      measurement.num_points < 1)
    return zero;
  const double n = static_cast<double>(measurement.num_points);
  const double z = supportDepth(measurement);
  const double sigma_z = params.sigma * z * z;
  // (J^T J / n)^-1 = C_fit n / rms^2, about the quadric's origin; moved to the support's centre
  // where a symmetry allows (a plane's origin slides in the plane, a cylinder's along its axis), so
  // that its rotation entries are tilts about the support rather than about a far-away origin.
  const QuadricClass quadric_class = measurement.quadric_camera.quadricClass();
  const Eigen::Vector3d centre = 0.5 * (measurement.extent_min + measurement.extent_max);
  Eigen::Isometry3d G = Eigen::Isometry3d::Identity();
  if (quadric_class == QuadricClass::kPlane && centre.allFinite())
    G.translation() = Eigen::Vector3d(0.0, centre.y(), centre.z());  // normal = quadric x
  else if (quadric_class == QuadricClass::kCylinder && centre.allFinite())
    G.translation() = Eigen::Vector3d(0.0, 0.0, centre.z());  // axis = quadric z
  const Eigen::MatrixXd to_centre = minimalAdjoint(quadric_class, G.inverse());
  Eigen::MatrixXd geometry = to_centre * fit * to_centre.transpose() * (n / (rms * rms));
  // A support narrower than a correlation cell sees a smooth error: an offset and the error's
  // slope, about sigma / L, not the sigma / width tilt that white noise over it would give. Its
  // rotation entries are scaled to those of a support one cell wide.
  Eigen::Vector3d sides = (measurement.extent_max - measurement.extent_min).cwiseAbs();
  std::sort(sides.data(), sides.data() + 3, std::greater<double>());
  const double cell = params.correlation_angle * z;
  const double narrow = sides.allFinite() ? std::min(1.0, sides[1] / cell) : 1.0;
  const QuadricClassDefinition& definition = classDefinition(quadric_class);
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(k);
  for (int j = 0; j < k; ++j) {
    int row = 0;
    definition.basis.col(j).cwiseAbs().maxCoeff(&row);
    if (row >= 3 && row < 6)  // a rotation entry (minimal columns: translation, rotation, scale)
      scale[j] = narrow;
  }
  geometry = scale.asDiagonal() * geometry * scale.asDiagonal();
  const Eigen::MatrixXd from_centre = minimalAdjoint(quadric_class, G);
  Eigen::MatrixXd model = from_centre * geometry * from_centre.transpose() *
                          (sigma_z * sigma_z / independentCells(measurement, params));
  return 0.5 * (model + model.transpose());
}

void MeasurementModelError::add(QuadricMeasurement& measurement, const Params& params) {
  const Eigen::MatrixXd model = covariance(measurement, params);
  if (model.rows() == measurement.covariance.rows() &&
      model.cols() == measurement.covariance.cols())
    measurement.covariance += model;
}

}  // namespace quadric_slam
