// Step 2 of the segmenter: curved-surface candidates from CGAL's Efficient RANSAC, run per
// image-grid connected component of the points no plane took (on a sub-sample): small inputs with a
// support threshold relative to their size converge in few RANSAC rounds, and a shape never spans
// two separate objects. The components run in parallel (Params::threads).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "quadric_slam/frontend/cgal_shape_detector.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/frontend/segmentation_frame.h"

namespace quadric_slam {

struct CurvedCandidates {
  // The sub-sample RANSAC saw: points, unit normals and pixel indices, each component's contiguous.
  std::vector<Eigen::Vector3d> points, normals;
  std::vector<int> pixels;
  // Shapes found (indices into the sub-sample), biggest first. CGAL's planes are kept: they absorb
  // flat patches that would otherwise become wide cylinders, and verification skips them.
  std::vector<CgalShapeDetector::Shape> shapes;
};

// 4-connected components of the valid, unused points (depth jumps break connectivity).
std::vector<std::vector<int>> freeComponents(const SegmentationFrame& frame,
                                             const QuadricSegmenter::Params& p);

// The candidates of the frame's free points (none when no curved class is enabled).
CurvedCandidates findCurvedCandidates(const SegmentationFrame& frame,
                                      const QuadricSegmenter::Params& p);

}  // namespace quadric_slam
