// The Kinect v1 (structured light) depth error model used by the simulator: axial noise growing
// with the square of the depth (Nguyen, Izadi, Lovell 2012; Khoshelham & Elberink 2012),
// quantisation of the disparity, and the places where the sensor returns no data (out of range,
// grazing incidence, along depth discontinuities, random dropout).
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>

#include "quadric_slam/sim/random.h"

namespace quadric_slam {

class KinectDepthModel {
 public:
  struct Params {
    double min_range = 0.5;  // closer true depths give no data (m)
    double max_range = 4.5;  // farther true depths give no data (m)
    // Axial noise sigma(z) = sigma_constant + sigma_quadratic * (z - sigma_reference_depth)^2 (m).
    double sigma_constant = 0.0012;      // m
    double sigma_quadratic = 0.0019;     // 1/m
    double sigma_reference_depth = 0.4;  // m
    // Disparity quantisation: depth z = focal * baseline / disparity, disparity measured in steps
    // of disparity_resolution pixels, so the depth step is z^2 * resolution / (focal * baseline).
    double focal_px = 580.0;  // IR camera focal length (px)
    double baseline = 0.075;  // projector-camera baseline (m)
    double disparity_resolution =
        0.125;                      // px (1/8 px sub-pixel disparity); 0 disables quantisation
    double max_incidence = 1.309;   // rad (75 deg): more oblique surfaces give no data
    int edge_dropout_px = 1;        // no data this many pixels on the far side of a discontinuity
    double edge_jump_ratio = 0.04;  // a neighbour nearer by more than this fraction of z is an edge
    double dropout_probability = 0.002;  // random isolated missing pixels, [0, 1)

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  KinectDepthModel() : KinectDepthModel(Params()) {}
  explicit KinectDepthModel(const Params& params);

  const Params& params() const { return params_; }

  // Axial noise standard deviation at depth z (m), before quantisation.
  double sigma(double z) const;
  // Depth quantisation step at depth z (m); 0 when quantisation is disabled.
  double depthStep(double z) const;
  // Expected standard deviation of a measurement at z: sigma and a uniform quantisation error,
  // sqrt(sigma^2 + step^2 / 12).
  double expectedStd(double z) const;
  // Rounds a depth to the nearest representable disparity.
  double quantise(double z) const;
  // One measurement of a surface at true depth z seen at the given cosine of the incidence angle
  // (between the viewing ray and the surface normal): NaN when there is no data. Edges are not
  // handled here (they need neighbours): see apply().
  float measure(double z_true, double cos_incidence, SimRandom& random) const;

  // Noisy depth image (CV_32FC1 metres, NaN = no data) from the true depth (CV_32FC1, NaN where
  // no surface) and the per-pixel cosine of incidence (CV_32FC1). Each row draws from its own
  // stream of (seed, row), so the result does not depend on threading.
  cv::Mat apply(const cv::Mat& depth_true, const cv::Mat& cos_incidence, std::uint64_t seed) const;

 private:
  // True when pixel (u, v) lies within edge_dropout_px of a nearer surface across a jump.
  bool nearEdge(const cv::Mat& depth_true, int u, int v) const;

  Params params_;
  double cos_max_incidence_;
};

}  // namespace quadric_slam
