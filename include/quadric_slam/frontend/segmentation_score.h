// Scoring a segmentation against per-pixel ground-truth surface ids (the synthetic generator's
// labels/<stamp>.png with the classes of quadrics_gt.yaml), accumulated over frames.
#pragma once

#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "quadric_slam/frontend/quadric_segmenter.h"

namespace quadric_slam {

class SegmentationScore {
 public:
  // truth_classes: surface id -> class name of the map schema (plane, sphere, cylinder, cone,
  // ellipsoid, ...); surfaces of other classes than the four primitives are not scored.
  // min_pixels: a surface is scored in a frame when it has at least this many valid pixels.
  SegmentationScore(std::map<int, std::string> truth_classes, int min_pixels);

  // truth: CV_16UC1 surface ids (0 = none), the size of segmentation.labels; valid: CV_8UC1,
  // non-zero where the depth is valid (labels of pixels without depth are not counted). A scored
  // surface is detected when a detection of its class has >= 50% of its pixels on the surface and
  // covers >= 30% of the surface's pixels. A detection is spurious when the majority of its pixels
  // lies on no surface or on a surface of another class (a general detection with the ellipsoid's
  // signature is of class "ellipsoid").
  void addFrame(const Segmentation& segmentation, const cv::Mat& truth, const cv::Mat& valid);

  // The same, and the parameter errors of the detections counted as found, against the true
  // shapes in the camera frame (surface id -> shape): plane normal angle (deg) and offset (m),
  // sphere centre (m) and radius (m), cylinder axis angle (deg, as lines) and radius (m), cone axis
  // angle (deg) and half angle (deg). Each error is kept with its range: the distance from the
  // camera to the centre of the detection's support (the sensor's noise grows with it).
  void addFrame(const Segmentation& segmentation, const cv::Mat& truth, const cv::Mat& valid,
                const std::map<int, PrimitiveShape>& truth_camera);

  struct Surface {
    std::string quadric_class;
    int frames_scored = 0, frames_detected = 0;
    double rate() const { return frames_scored ? double(frames_detected) / frames_scored : 0.0; }
  };
  const std::map<int, Surface>& surfaces() const { return surfaces_; }
  // Scored surfaces not detected in the last frame added.
  const std::vector<int>& lastMissed() const { return last_missed_; }
  // The spurious detections of the last frame added, as "<class> <label> on <surface class>
  // <surface id>" ("on no surface" where the majority has no surface).
  const std::vector<std::string>& lastSpurious() const { return last_spurious_; }
  int frames() const { return frames_; }
  int spurious() const { return spurious_; }
  double spuriousPerFrame() const { return frames_ ? double(spurious_) / frames_ : 0.0; }
  // The spurious detections whose majority lies on a surface of a class the segmenter has no
  // model for (e.g. an ellipsoid taken as a sphere); included in spurious().
  int spuriousOnUnmodelled() const { return spurious_unmodelled_; }
  double spuriousPerFrameOnModelled() const {
    return frames_ ? double(spurious_ - spurious_unmodelled_) / frames_ : 0.0;
  }
  // Per class name: the two error kinds above, one entry per found detection whose range is in
  // [min_range, max_range) (m).
  struct ParameterErrors {
    std::vector<double> first, second;  // plane angle/offset; sphere centre/radius; ...
  };
  std::map<std::string, ParameterErrors> parameterErrors(double min_range, double max_range) const;
  // Median of a list (0 when empty).
  static double median(std::vector<double> values);
  // Per surface its detection rate; the spurious detections; per class and band of range (0-2 m,
  // 2-4 m, beyond 4 m) the median parameter errors.
  std::string report() const;

 private:
  std::map<int, std::string> truth_classes_;
  int min_pixels_;
  std::map<int, Surface> surfaces_;
  int frames_ = 0, spurious_ = 0, spurious_unmodelled_ = 0;
  std::map<std::string, int> spurious_kinds_;  // "<detected class> on <surface class>" -> count
  struct FitError {
    double range, first, second;
  };
  std::map<std::string, std::vector<FitError>> errors_;  // class name -> found detections' errors
  std::vector<int> last_missed_;
  std::vector<std::string> last_spurious_;
};

}  // namespace quadric_slam
