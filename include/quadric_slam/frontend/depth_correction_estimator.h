// Estimates a depth camera's fixed disparity distortion (frontend/depth_correction.h) from its own
// frames, without ground truth: flat surfaces. In disparity a plane is affine in the pixel
// coordinates (f b / z = a + b u + c v exactly, for any plane not through the camera centre), so
// over a planar segment the measured disparity is that affine function minus the distortion D(u,
// v):
//   f b / z'_i = a_s + b_s u_i + c_s v_i - D(u_i, v_i) + noise.
// Each segment brings its own three plane parameters, eliminated as they come (Schur complement);
// D is shared by all segments of all frames. An affine D is what every segment's plane absorbs,
// so it cannot be seen this way and is fixed to zero (what is corrected is the bend, not a tilt or
// an offset of the disparity); nodes between the data are held smooth by a second-difference
// penalty. The sensor's disparity noise is roughly the same at every range (its depth noise grows
// as z^2), so every pixel has the same weight.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "quadric_slam/frontend/depth_correction.h"

namespace quadric_slam {

class DepthCorrectionEstimator {
 public:
  struct Params {
    // Grid nodes (>= 3 each): 17 x 13 puts them 40 px apart on a 640 x 480 image, enough for the
    // distortion's wavelengths of 160 px and up.
    int cols = 17;
    int rows = 13;
    // Weight of each node's squared second difference along rows and columns, in pixels' worth of
    // data (> 0): the data of a node's cell outweighs it, while nodes without data follow their
    // neighbours.
    double smoothness = 100.0;
    // Segments with fewer usable pixels are skipped (>= 10).
    int min_pixels = 2000;
    // Every pixel_stride-th pixel of a segment in u and v is used (>= 1).
    int pixel_stride = 2;
    // Pixels farther than this many RMS from their segment's first plane fit are left out (> 0).
    double outlier_sigmas = 3.0;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  // width x height image; focal_baseline: the sensor's focal length (px) times its baseline (m).
  DepthCorrectionEstimator(int width, int height, double focal_baseline, const Params& params);

  // One planar segment: its pixels (u, v) and measured depths z' (m, finite, > 0), same order.
  // Returns the pixels used (0 when the segment was too small after the stride and outliers).
  int addPlane(const std::vector<Eigen::Vector2d>& pixels, const std::vector<double>& depths);

  int segments() const { return segments_; }
  long long pixels() const { return pixels_; }

  // The distortion that best explains the segments added so far (affine part zero). Throws
  // std::runtime_error when no segment was added.
  DepthCorrection solve() const;
  // RMS of the segments' disparity residuals (px) before and after the correction, over the data
  // added; computed from the accumulated sums (S0 - 2 b.D + D.H.D), no pixel is revisited.
  struct Fit {
    double rms_before = 0.0;
    double rms_after = 0.0;
  };
  Fit fit(const DepthCorrection& correction) const;

 private:
  int width_, height_;
  double focal_baseline_;
  Params params_;
  int nodes_;
  Eigen::MatrixXd information_;  // reduced normal equations in D (after eliminating the planes)
  Eigen::VectorXd vector_;
  double reduced_sum_sq_ = 0.0;  // sum of squared residuals of the per-segment planes, D = 0
  int segments_ = 0;
  long long pixels_ = 0;
};

}  // namespace quadric_slam
