// The model error of a quadric measurement fitted to depth: the part of a depth camera's error that
// does not average away over a segment's pixels.
//
// The segmenter's fit covariance, rms^2 (J^T J)^-1 over the n supporting points
// (frontend/shape_refiner.h), treats every pixel's error as independent. A structured-light depth
// camera's error is not: its disparity carries a fixed, smooth distortion pattern and a radial
// bend towards the image corners (Smisek et al. 2011; Herrera et al. 2012), so a flat surface is
// measured bent, and its fitted orientation and offset are off by an amount that shrinks only
// with the number of independent patches of that pattern the support covers, not with n. A small
// fragment of a large surface is then fitted several degrees off while claiming a fraction of a
// degree, and the association gate, the window weights and the landmark merger all trust it.
//
// The model: the systematic depth error has standard deviation sigma(z) = sigma * z^2 (the
// distortion lives in disparity, so a depth error grows with the square of the depth z), and is
// correlated over an angle theta as seen from the camera, i.e. over L(z) = theta z on the surface.
// A support of area A (the two largest sides of its extent box) covers
//   n_eff = clamp(A / L(z)^2, 1, n)
// independent cells, and the fit's parameters pick up the covariance
//   C_model = sigma(z)^2 (J^T J / n)^-1 / n_eff,
// the least-squares covariance of n_eff independent samples of that noise spread over the same
// support. The geometry (J^T J / n)^-1 is recovered from the fit's own covariance,
// C_fit = rms^2 (J^T J)^-1, as C_fit n / rms^2, so every class is handled alike without the
// supporting points. The measurement's covariance becomes C_fit + C_model.
//
// General quadrics are left alone: their covariance already holds the segmenter's view-to-view
// model error (frontend/ellipsoid_candidate.h, general_model_sigma).
#pragma once

#include <Eigen/Core>

#include "quadric_slam/types/observation.h"

namespace quadric_slam {

struct MeasurementModelError {
  struct Params {
    // sigma: 1-sigma systematic depth error at 1 m depth (m, [0, 0.1]; 0 disables the term).
    // Default 0 (off): 0.002 is the calibrated value (config/mapping.yaml), not yet the default.
    double sigma = 0.0;
    // theta: angle over which that error is correlated, seen from the camera (rad, (0, 1.5]).
    double correlation_angle = 0.2;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  // Depth of the centre of the support's extent box in the camera frame (m, >= 0.1: a floor
  // keeps the term finite for a surface at the camera).
  static double supportDepth(const QuadricMeasurement& measurement);
  // n_eff above: independent correlation cells the support covers, in [1, max(1, num_points)].
  static double independentCells(const QuadricMeasurement& measurement, const Params& params);
  // C_model above (k x k, the class's minimal space); a zero matrix when the term does not apply
  // (general quadric, sigma 0, no fit covariance or residual to recover the geometry from).
  static Eigen::MatrixXd covariance(const QuadricMeasurement& measurement, const Params& params);
  // measurement.covariance += covariance(measurement, params).
  static void add(QuadricMeasurement& measurement, const Params& params);
};

}  // namespace quadric_slam
