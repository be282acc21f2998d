// A depth camera's fixed depth distortion, undone. A structured-light sensor (Kinect v1) measures
// disparity, and its depth carries a per-device disparity error that does not change from frame to
// frame: a smooth bowl and a low-frequency pattern over the image (Smisek et al. 2011, Herrera et
// al. 2012), a fraction of a pixel that bends a flat wall by about a centimetre at 3 m. Every view
// of a surface sees it bent differently, which no pose fits: on the generated room it is what
// holds the trajectory's error above a centimetre.
//
// The model: measured disparity d' = f b / z' = f b / z - D(u, v), with D a grid of disparity
// offsets (px) over the image, bilinear between the nodes; the true depth is
//   z = f b / (f b / z' + D(u, v)),
// and a back-projected point moves along its ray by z / z'. D is estimated from the sensor's own
// frames (frontend/depth_correction_estimator.h): the file is written by the calibrate_depth tool
// and read by io/depth_correction_yaml.h.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>
#include <vector>

namespace quadric_slam {

class DepthCorrection {
 public:
  // No correction (empty()).
  DepthCorrection() = default;
  // A grid of cols x rows nodes (>= 2 each) spanning an image of width x height pixels (node
  // (i, j) at pixel (i (width - 1) / (cols - 1), j (height - 1) / (rows - 1))), node offsets
  // row-major (disparity px), and the sensor's focal length times its baseline (px m, > 0).
  // Throws std::invalid_argument naming the bad argument.
  DepthCorrection(int width, int height, int cols, int rows, std::vector<double> offsets,
                  double focal_baseline);

  bool empty() const { return offsets_.empty(); }
  int width() const { return width_; }
  int height() const { return height_; }
  int cols() const { return cols_; }
  int rows() const { return rows_; }
  double focalBaseline() const { return focal_baseline_; }
  const std::vector<double>& offsets() const { return offsets_; }

  // D(u, v): bilinear between the nodes (px); pixels outside the image take the border's.
  double offsetAt(double u, double v) const;
  // The corrected depth of a pixel measured at z' (m); z' itself when empty() or not finite; NaN
  // when the corrected disparity is not positive (a negative offset larger than the disparity).
  double correctedDepth(double u, double v, double z_measured) const;
  // Moves every finite point of an organized cloud back-projected with the given decimation
  // (point (col, row) from pixel (col decimation, row decimation)) along its ray to the corrected
  // depth (no data where the corrected disparity is not positive). Nothing when empty(). Throws
  // std::invalid_argument when the cloud's full-resolution size is not the correction's image.
  void apply(pcl::PointCloud<pcl::PointXYZ>* cloud, int decimation) const;

 private:
  int width_ = 0, height_ = 0, cols_ = 0, rows_ = 0;
  std::vector<double> offsets_;
  double focal_baseline_ = 0.0;
  std::vector<float> pixel_offsets_;  // D at every pixel, row-major (apply() reads these)
};

// The bilinear weights of pixel (u, v) on a grid as DepthCorrection's: nodes[k] (row-major index)
// with weights[k], k < 4.
struct GridWeights {
  int nodes[4] = {0, 0, 0, 0};
  double weights[4] = {0, 0, 0, 0};
};
GridWeights gridWeights(double u, double v, int width, int height, int cols, int rows);

}  // namespace quadric_slam
