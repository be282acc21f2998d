// Photometric refinement of a depth alignment, along the directions its geometry leaves free or
// jointly with the depth's information as a prior (issue 12). A wall that fills the view fixes the
// camera's distance to it and two rotations; the motion along it is measured by the wall's texture
// only. The residual of a current pixel is the difference between its intensity and the keyframe
// image's where its 3D point lands (the direct method of Kerl, Sturm and Cremers, "Robust Odometry
// Estimation for RGB-D Cameras", ICRA 2013), with Huber weights, minimised by Gauss-Newton coarse
// to fine over the given directions: without a prior the point-to-plane answer in the others is
// kept as it is; with the depth's information as a prior (what OdometryTracker does) all six
// directions move and the depth weighs against the intensities. A brightness offset between the
// two images is estimated with the pose (a real camera's auto exposure).
#pragma once

#include <vector>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {

// An image's intensity at several resolutions (level 0 the image's own, each next one half of the
// previous, cv::pyrDown), as float grey, with its horizontal and vertical derivatives per pixel.
struct IntensityPyramid {
  std::vector<cv::Mat> intensity, gradient_x, gradient_y;  // CV_32F each

  // From an 8-bit grey (CV_8UC1) or RGB/BGR (CV_8UC3) image; throws std::invalid_argument on
  // another type, an empty image, or levels outside [1, 6].
  static IntensityPyramid fromImage(const cv::Mat& image, int levels);
  bool empty() const { return intensity.empty(); }
  int width() const { return empty() ? 0 : intensity[0].cols; }
  int height() const { return empty() ? 0 : intensity[0].rows; }
};

class PhotometricRefinement {
 public:
  using Cloud = pcl::PointCloud<pcl::PointNormal>;
  using Directions = Eigen::Matrix<double, 6, Eigen::Dynamic>;

  struct Params {
    // Pyramid levels used, coarsest first (the pyramids must hold at least this many).
    int levels = 3;
    int max_iterations = 8;  // Gauss-Newton iterations per level
    // At most this many current pixels per level, taken with the strongest intensity gradient
    // (the others carry no information along the image).
    int max_points = 3000;
    // Pixels whose intensity gradient (grey levels per pixel of the level) is weaker are not used.
    double min_gradient = 3.0;
    // Huber threshold of the intensity residual (grey levels).
    double huber = 8.0;
    // Fewer usable pixels than this at the finest level: no refinement.
    int min_points = 200;
    // The refinement is refused when it moves the pose further than this from the start (m and
    // rad, along the free directions): the geometry's basin is the trusted one.
    double max_translation = 0.10;
    double max_rotation = 0.10;
    // Iterations stop when the step is below these (m, rad).
    double convergence_translation = 1e-5;
    double convergence_rotation = 1e-5;
    void validate() const;  // throws std::invalid_argument naming the field and its range
  };

  struct Result {
    Eigen::Isometry3d T_reference_current = Eigen::Isometry3d::Identity();
    bool refined = false;                  // false: the start is returned unchanged (see message)
    int points = 0;                        // pixels used at the finest level
    double rms_before = 0, rms_after = 0;  // weighted intensity RMS at the finest level
    // The brightness change between the keyframe's image and the frame's that the refinement
    // estimated with the pose (grey levels, keyframe minus frame).
    double brightness_offset = 0;
    // Information (J^T W J over sigma^2) along the free directions at the finest level, k x k.
    Eigen::MatrixXd information;
    std::string message;  // why not refined (empty when refined)
  };

  explicit PhotometricRefinement(const Params& params);
  const Params& params() const { return params_; }

  // Refines T_reference_current (left perturbation exp(xi^) T, xi = (v, omega) in the reference
  // frame, as pose_math::retractLeft) along the columns of free (6 x k, orthonormal, k in 1..6)
  // by matching current's intensities to reference's. current_cloud is the organized cloud of the
  // current frame in its camera frame, at the pyramids' resolution or an integer decimation of it;
  // intrinsics are those of the pyramids' level 0. Never throws on bad data: a start that cannot
  // be improved is returned with refined = false.
  // prior_information (6 x 6, left perturbation from the start): a Gaussian prior on the move,
  // e.g. the depth's information along the directions it measured; the intensities' residuals are
  // then weighed as information by their variance. Zero (the default): the intensities alone.
  Result refine(const IntensityPyramid& reference, const IntensityPyramid& current,
                const Cloud& current_cloud, const CameraIntrinsics& intrinsics,
                const Eigen::Isometry3d& T_reference_current, const Directions& free,
                const Matrix6d& prior_information = Matrix6d::Zero()) const;

 private:
  Params params_;
};

// d(intensity)/d(xi) of the image at the projection of P (a point in the image's camera frame)
// under the left perturbation exp(xi^) P, xi = (v, omega): grad I (gx, gy, per pixel) times the
// pinhole projection's Jacobian (focal lengths fx, fy) times dP/dxi = [I, -[P]x].
Eigen::Matrix<double, 1, 6> intensityJacobian(const Eigen::Vector3d& P, double gx, double gy,
                                              double fx, double fy);

// The directions a covariance leaves free: its eigenvectors whose variance is at least fraction x
// degenerate_variance (the point-to-plane ICP puts degenerate_variance along the directions it
// cannot measure), as the columns of a 6 x k matrix (k = 0 when none).
PhotometricRefinement::Directions freeDirections(const Matrix6d& covariance,
                                                 double degenerate_variance, double fraction);

// The information of a covariance on the directions it measured (the complement of
// freeDirections with the same arguments), with floor (6 x 6, added to the covariance there)
// bounding how sure a measurement can be; zero along the free ones.
Matrix6d measuredInformation(const Matrix6d& covariance, double degenerate_variance,
                             double fraction, const Matrix6d& floor);

}  // namespace quadric_slam
