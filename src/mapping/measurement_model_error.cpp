#include "quadric_slam/mapping/measurement_model_error.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/types/param_checks.h"

namespace quadric_slam {

void MeasurementModelError::Params::validate() const {
  const ParamRangeCheck requireRange("MeasurementModelError::Params");
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
  // (J^T J / n)^-1 = C_fit n / rms^2.
  const Eigen::MatrixXd geometry = fit * (n / (rms * rms));
  Eigen::MatrixXd model = geometry * (sigma_z * sigma_z / independentCells(measurement, params));
  return 0.5 * (model + model.transpose());
}

void MeasurementModelError::add(QuadricMeasurement& measurement, const Params& params) {
  const Eigen::MatrixXd model = covariance(measurement, params);
  if (model.rows() == measurement.covariance.rows() &&
      model.cols() == measurement.covariance.cols())
    measurement.covariance += model;
}

}  // namespace quadric_slam
