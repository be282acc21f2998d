// How much noisier the observations are than their covariances say, estimated from the data: a
// robust variance component estimate (Helmert; Foerstner 1979), one factor for the sensor.
// A segment's fit covariance, sigma^2 (J^T J)^-1 over thousands of pixels, describes the pixel
// noise only; a depth camera's systematic error (disparity distortion, a bend that does not
// average away), the segmentation's border pixels and the shape model's own error make the
// observations of a surface scatter tens of times more than that between views (whitened
// residuals of 26-68 sigma in the batch on the generated and the real sequences). Weighted as
// claimed, a few such observations outweigh a keyframe's odometry. With whitened residuals r_i of
// dimension k_i, the variance factor is
//   s^2 = max(1, median_i |r_i|^2 / median(chi2_k_i)),
// the median keeping the observations that are outliers (a wrong association, a spurious segment)
// out of the estimate. One factor for all classes: the depth camera's error is common to every
// surface (per-class factors let the few, often spurious curved landmarks of a real room outweigh
// its planes: real kitchen SLAM ATE 2.66 cm against 2.50 with one factor). It never goes below 1:
// the covariances stay a floor of what the data may claim.
#pragma once

#include <vector>

namespace quadric_slam {

struct WhitenedResidual {
  int dimension = 0;          // k, the residual's size (the class's minimal dimension)
  double squared_norm = 0.0;  // |r|^2 under the covariance as the measurement stated it
};

// The variance factor (>= 1) of `residuals`; 1 for none. Throws std::invalid_argument for a
// residual of dimension < 1.
double observationVarianceFactor(const std::vector<WhitenedResidual>& residuals);

}  // namespace quadric_slam
