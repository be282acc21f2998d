// Quadric segmentation of one depth frame: organized cloud with normals -> planes, spheres,
// cylinders, cones and ellipsoids (class general) (the paper's front-end, Section IV), each with
// its least-squares fit, covariance, support and image extent, plus a label image.
//
// Pipeline (all in the camera frame), one unit per step, segment() the orchestrator:
//  0. on a grid decimated by Params::decimation (multi_resolution_labels.h), the frame's valid
//     points (segmentation_frame.h);
//  1. planes by region growing over the image grid (plane_region_grower.h), flatness-checked;
//  2. (on the grid decimated again by Params::curved_decimation, when above 1, steps 2-3; their
//     segments then labelled on the plane grid's free points) CGAL Efficient RANSAC (Schnabel et
//     al. 2007) with sphere, cylinder, cone (and plane, to absorb small planar patches) on a
//     sub-sample of each image-grid connected component of the remaining points, components in
//     parallel; a CGAL plane whose normals bend (the grower's curvature test) becomes the cylinder
//     its normals describe when that fits better (a far, narrow strip of a cylinder)
//     (curved_candidates.h; starting shapes: curved_shape_starts.h);
//  3. for each CGAL shape, biggest first (curved_verification.h): range and degeneracy filters
//     (huge-radius cylinders, near-flat cones and big spheres are tested against a plane; thin
//     cones against a cylinder), least-squares refinement, re-assignment of all free pixels near
//     the surface with agreeing normals, the largest image-grid connected component (with the
//     large ones on the surface's other face: an open bin's inner wall), minimum support,
//     refinement again (shape_refiner.h); near-flat (plane RMS close AND normals not bending
//     like the shape) and shape (RMS against a general quadric that is a surface) tests; where
//     the shape test finds an ellipsoid, the ellipsoid is re-assigned, refined and reported
//     instead (class general, detect_general);
//  4. the labels brought back to full resolution (multi_resolution_labels.h) and the rim of each
//     segment, where normals are missing, completed (boundary_labels.h).
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "quadric_slam/frontend/plane_region_grower.h"
#include "quadric_slam/frontend/primitive_shape.h"
#include "quadric_slam/frontend/shape_refiner.h"
#include "quadric_slam/types/observation.h"  // ImageRoi

namespace quadric_slam {

// One segmented primitive, in the frame of the input cloud (the camera frame).
struct QuadricDetection {
  PrimitiveShape shape;
  // Covariance of the fit in the class's minimal coordinates (Table II, geometry/quadric_classes.h
  // basis: plane (rho1, phi2, phi3); sphere (rho1..3, s); cylinder (rho1, rho2, phi1, phi2, s);
  // cone (rho1..3, phi1, phi2, s); general (rho1..3, phi1..3, alpha, beta, gamma)), a right
  // (body-frame) perturbation of shape.quadric() with s the radial entry of S: sigma^2 (J^T J)^-1
  // of the least squares.
  Eigen::MatrixXd covariance;
  // Supporting points (cloud grid): the labelled pixels, boundary points without normals included
  // (boundary_labels.h); the fit, its RMS and covariance use the points with normals.
  int num_points = 0;
  double fit_rms = 0.0;  // RMS geometric distance of the fit's points (m)
  std::uint16_t label = 0;
  ImageRoi roi;  // bounding box of the supporting pixels in the cloud's grid
  // Axis-aligned box of the supporting points in the frame of shape.quadric() (m).
  Eigen::Vector3d extent_min = Eigen::Vector3d::Zero(), extent_max = Eigen::Vector3d::Zero();
};

// Wall-clock time of the segmenter's stages for one frame (ms), for benchmarks and diagnostics.
struct SegmentationTimings {
  double planes_ms = 0.0;     // region growing, merging and plane refinement
  double ransac_ms = 0.0;     // sub-sampling and CGAL Efficient RANSAC
  double verify_ms = 0.0;     // filters, refinement and re-assignment of curved candidates
  double upsample_ms = 0.0;   // decimation and full-resolution labelling (decimation > 1)
  double boundary_ms = 0.0;   // labels of boundary points without normals (boundary_labels.h)
  int ransac_points = 0;      // points given to CGAL
  int ransac_candidates = 0;  // shapes CGAL returned
  int curved_verified_again =
      0;  // verdicts reached in parallel, then redone in order (threads > 1)
};

struct Segmentation {
  SegmentationTimings timings;
  std::vector<QuadricDetection> detections;
  // CV_16UC1, the cloud's size: 0 = unassigned, else the label of the detection owning the point.
  cv::Mat labels;
};

class QuadricSegmenter {
 public:
  struct Params {
    // Points outside [min_range, max_range] of depth (z, m) are ignored. 0 < min < max.
    double min_range = 0.3;
    double max_range = 4.5;
    // The segmentation runs on every decimation-th pixel in u and v (point counts and strides
    // below are scaled accordingly) and the labels are then assigned at full resolution: each
    // pixel takes a neighbouring sample's label when it fits that surface. [1, 8]. Default 2.
    int decimation = 2;
    // The curved stages (CGAL candidates, verification) run on the segmenter's grid decimated
    // once more by this factor; their segments are then labelled on that grid's free points as
    // the full-resolution labelling does (multi_resolution_labels.h). Planes stay on the finer
    // grid. Counts and strides of the curved stages scale with it. [1, 8]; 1 = the same grid
    // (default). 2 costs 16 % fewer instructions per frame, with about the same curved recall on
    // generated sequences but fewer of the real table-top cylinders (config/segmentation.yaml).
    int curved_decimation = 1;
    // Points with depth but without a normal (next to depth edges and holes) join an adjacent
    // segment whose surface they fit, up to this many pixels out (frontend/boundary_labels.h),
    // [0, 10]; 0 = off. Default 3.
    int boundary_rings = 3;
    // Worker threads of the full-resolution labelling (decimation > 1), [1, 64]. Default 2.
    int threads = 2;
    // Planes (region growing); its min_points is in points of the cloud grid.
    PlaneRegionGrower::Params planes;
    // Curved shapes.
    bool detect_spheres = true, detect_cylinders = true, detect_cones = true;
    // Every cgal_stride-th free pixel in u and v goes to CGAL, [1, 16]. Default 3.
    int cgal_stride = 3;
    // A larger stride is used in a component that would give CGAL more points than this, >= 100.
    int cgal_max_points = 500;
    // CGAL Efficient RANSAC: probability of missing the largest shape, (0, 1); minimum support
    // (sub-sampled points), >= 4; distance epsilon (m), > 0; cluster epsilon (m), > 0; normal
    // threshold (cosine), (0, 1).
    double cgal_probability = 0.2;
    int cgal_min_points = 40;
    double cgal_epsilon = 0.008;
    double cgal_cluster_epsilon = 0.03;
    double cgal_normal_threshold = 0.85;
    // CGAL runs once per connected component of the free points; its minimum support there is
    // max(cgal_min_points, cgal_min_fraction * sub-sampled component size), [0, 1).
    double cgal_min_fraction = 0.08;
    // true: the curved candidates come from GridShapeRansac (grid_shape_ransac.h: the component's
    // sample connected through the image grid, proposals scored directly, each class's best
    // refitted before the classes are compared) with the cgal_* parameters (cluster epsilon
    // aside); false: from CGAL's Efficient RANSAC. At a quarter of CGAL's instructions the same
    // curved recall and spurious count on the harsh generated scenes, but fewer frames of a far
    // cone and more thin cylinders on surfaces cut by the image border
    // (docs/segmentation/README.md). Default false.
    bool grid_ransac = false;
    // Assignment of full-resolution pixels to a curved shape: distance threshold
    // max(min_distance, distance_factor * z^2) of the planes, and this normal angle (rad),
    // (0, pi/2).
    double curved_max_normal_angle = 0.6;
    // Smallest curved segment (points of the cloud grid), >= 4.
    int min_curved_points = 250;
    // Plausible sizes (m, rad): sphere radius, cylinder radius, cone half angle.
    double min_sphere_radius = 0.03, max_sphere_radius = 0.6;
    double min_cylinder_radius = 0.01, max_cylinder_radius = 0.5;
    double min_cone_half_angle = 0.05, max_cone_half_angle = 1.2;
    // Degeneracy: a curved fit whose RMS is not clearly better than a plane's (plane RMS <
    // plane_rms_ratio * curved RMS) is a plane, unless its normals bend like it (shape operator
    // above the plane grower's max_curvature, within a factor 2 of the shape's curvature: the
    // depth noise hides the sag of a far, narrow arc); a cone or cylinder whose RMS is not clearly
    // better than that of a simpler class (cone -> cylinder -> sphere; RMS of the simpler <
    // cylinder_rms_ratio * its own) becomes the simpler class. Ratios >= 1.
    // A cylinder is also fitted as a cone (a truncated cone with a small half angle looks like a
    // cylinder) and becomes one when the cone's RMS is below its own / cylinder_rms_ratio or the
    // cone is significantly better over the independent points (curved_model_selection.h).
    // A plane CGAL finds on bending normals becomes a cylinder candidate when the normals'
    // cylinder fits better, or within plane_rms_ratio where the depth noise exceeds cgal_epsilon.
    double plane_rms_ratio = 1.5;
    double cylinder_rms_ratio = 1.15;
    // Shape test: a curved fit whose RMS exceeds quadric_rms_ratio times that of a general quadric
    // fitted to the same points (general_quadric_fit.h) has residuals of shape, not noise (e.g. a
    // sphere on an ellipsoid) and is dropped; not when the general quadric fits the noise band
    // with two close sheets that split neighbouring points (under 3/4 of the grid neighbours on
    // one sheet), which undercuts any true surface's RMS, nor when along the pixels' rays it
    // explains the depths no better than the fit (ray_residual.h). The test also runs on the
    // points with the unsegmented surface they continue into without a depth jump, when one
    // quadric fits that at least as closely as the fit its points (curved_verification.h).
    // >= 1; default 1.3.
    double quadric_rms_ratio = 1.3;
    // Report what the shape test finds as a detection of class general when the general quadric
    // is an ellipsoid with semi-axes within [min_sphere_radius, max_sphere_radius]
    // (ellipsoid_candidate.h): re-assigned, refined on its 9 minimal parameters (shape_refiner.h)
    // and held to max_rms_factor like the other curved shapes. Default true.
    bool detect_general = true;
    // Model error of a general detection (m, [0, 0.1]): added to its least-squares covariance as
    // ellipsoid_candidate.h's ellipsoidModelCovariance (translation, rotation and scale entries
    // scaled from this 1-sigma error of the surface) so that the mapper's gates and weights see
    // the view-to-view scatter of one-sided fits. Default 0.01.
    double general_model_sigma = 0.01;
    // Largest fit RMS of a curved segment, relative to its distance threshold at the median
    // depth, (0, 10].
    double max_rms_factor = 0.6;
    // Least-squares refinement.
    ShapeRefiner::Params refiner;
    // Seed of CGAL's random sampling (fixed: the same frame gives the same result).
    unsigned int random_seed = 1;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  explicit QuadricSegmenter(const Params& params);

  // cloud: organized, normals NaN where unknown. Throws std::invalid_argument when unorganized.
  Segmentation segment(const pcl::PointCloud<pcl::PointNormal>& cloud) const;

  const Params& params() const { return params_; }

 private:
  // segment() without the boundary completion.
  Segmentation segmentWithNormals(const pcl::PointCloud<pcl::PointNormal>& cloud) const;

  Params params_;
};

// A colour per label (0 black) as in the paper's Fig. 2: CV_8UC3 in RGB order.
cv::Mat colouriseLabels(const cv::Mat& labels);

}  // namespace quadric_slam
