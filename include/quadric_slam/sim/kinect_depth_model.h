// The Kinect v1 (structured light) depth error model used by the simulator: axial noise growing
// with the square of the depth (Nguyen, Izadi, Lovell 2012; Khoshelham & Elberink 2012),
// quantisation of the disparity, and the places where the sensor returns no data (out of range,
// grazing incidence, along depth discontinuities, random dropout).
//
// Two presets. `nguyen`: the published axial model with independent per-pixel noise, kinder than
// the sensor. `harsh` (the default): calibrated on real Kinect v1 frames (tool
// measure_depth_noise on TUM fr1/fr2/fr3 and 7-Scenes frames): the axial sigma scaled up, a
// low-frequency radial disparity distortion that bends flat surfaces towards the image corners
// (the fixed pattern that Smisek et al. 2011 and Herrera et al. 2012 calibrate in disparity
// space, hence a depth error growing with z^2), and spatially correlated noise (the disparity is
// found by matching a window of the speckle pattern, so neighbouring pixels share their error).
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

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

    // Projector shadow: the projector sits projector_side * baseline along the camera's x axis
    // (+1: to the right in the image, as on the Kinect v1; 0: no shadow), so a background pixel
    // the projector cannot light, beside a nearer surface, gets no data: a band
    // f b (1/z_near - 1/z_far) pixels wide on the opposite side of every foreground object.
    int projector_side = 1;

    // --- harsh-model terms (all 0 in the nguyen preset) ---
    // Multiplies sigma(z) above (>= 0; 1 = Nguyen's fit).
    double sigma_scale = 1.2;
    // Radial disparity distortion: the measured depth exceeds the true one by
    //   dz = z^2 / (focal_px * baseline) * (distortion_r2 r^2 + distortion_r4 r^4)
    // with r the distance from the image centre, 1 at the corners. Coefficients in disparity px.
    double distortion_r2 = 0.05;
    double distortion_r4 = 0.0;
    // A fixed (per-device, not per-frame) smooth disparity pattern added to the same excess, as
    // the per-pixel distortion images of Smisek et al. 2011 and Herrera et al. 2012: a sum of
    // plane waves with wavelengths in [pattern_wavelength_px, 2 pattern_wavelength_px], scaled to
    // an RMS of pattern_amplitude disparity px over the image; its shape is set by pattern_seed.
    double pattern_amplitude = 0.05;       // disparity px (RMS), >= 0
    double pattern_wavelength_px = 160.0;  // px, > 0
    int pattern_seed = 7;                  // >= 0
    // Share of the noise variance that is spatially correlated, [0, 1]: white Gaussian noise
    // low-pass filtered by a Gaussian of correlation_px standard deviation (px) and rescaled to
    // unit variance; its autocorrelation at lag L is exp(-L^2 / (4 correlation_px^2)).
    double correlated_fraction = 0.85;
    double correlation_px = 4.0;  // > 0 px

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  // Preset names accepted by paramsForModel: "harsh", "nguyen".
  static Params nguyenParams();
  static Params harshParams();
  // Throws std::invalid_argument for an unknown name.
  static Params paramsForModel(const std::string& name);
  // Sets only the terms that tell the presets apart (sigma_scale, distortion_*, pattern_*,
  // correlated_fraction, correlation_px) to those of the named preset; ranges, dropout and
  // quantisation are kept. Throws std::invalid_argument for an unknown name.
  static void applyModel(const std::string& name, Params* params);

  KinectDepthModel() : KinectDepthModel(harshParams()) {}
  explicit KinectDepthModel(const Params& params);

  const Params& params() const { return params_; }

  // Axial noise standard deviation at depth z (m), before quantisation (sigma_scale applied).
  double sigma(double z) const;
  // Systematic radial depth excess (m) at true depth z and normalised image radius r (1 at a
  // corner); the fixed pattern is added in apply().
  double distortion(double z, double r) const;
  // The fixed disparity pattern (CV_32FC1, px) over an image of the given size.
  cv::Mat disparityPattern(cv::Size size) const;
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
  // The same with a given standard-normal noise draw and normalised image radius r.
  float measure(double z_true, double cos_incidence, double r, double unit_noise,
                SimRandom& random) const;

  // Noisy depth image (CV_32FC1 metres, NaN = no data) from the true depth (CV_32FC1, NaN where
  // no surface) and the per-pixel cosine of incidence (CV_32FC1). Each row draws from its own
  // streams of (seed, row), so the result does not depend on threading. The image centre is
  // the centre of the radial distortion.
  cv::Mat apply(const cv::Mat& depth_true, const cv::Mat& cos_incidence, std::uint64_t seed) const;

 private:
  // True when pixel (u, v) lies within edge_dropout_px of a nearer surface across a jump.
  bool nearEdge(const cv::Mat& depth_true, int u, int v) const;
  // Blanks (NaN) the pixels of one row of `out` that the projector cannot light.
  void castProjectorShadow(const float* z_true, float* out, int width) const;
  // Unit-variance noise field of the given size: white and low-pass parts mixed by
  // correlated_fraction.
  cv::Mat unitNoise(cv::Size size, std::uint64_t seed) const;

  Params params_;
  double cos_max_incidence_;
};

}  // namespace quadric_slam
