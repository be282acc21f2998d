// Multi-resolution labelling: the segmenter runs on a grid decimated by d (Params::decimation) and
// brings its segments back to the full-resolution grid.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <vector>

#include "quadric_slam/frontend/quadric_segmenter.h"

namespace quadric_slam {

// The parameters of a grid decimated by d: counts of points scale with 1 / d^2, strides with 1 / d.
QuadricSegmenter::Params coarseParams(const QuadricSegmenter::Params& p, int d);

// Every d-th point of an organized cloud in u and v ((width / d) x (height / d)).
pcl::PointCloud<pcl::PointNormal> decimated(const pcl::PointCloud<pcl::PointNormal>& cloud, int d);

// Full-resolution labels from a segmentation of the grid decimated by d: each valid pixel takes
// the label of a neighbouring coarse sample whose surface it fits (distance threshold and normal
// agreement, as on the coarse grid; no normal needed within 3 x the fit's RMS of a surface that is
// the only one among the neighbouring samples);
// support, fit RMS, ROI, extent and covariance follow the full-resolution points. Pixels flagged in
// taken (one flag per point of cloud; empty: none) stay unlabelled: those other segments hold.
Segmentation upsample(const pcl::PointCloud<pcl::PointNormal>& cloud, Segmentation coarse, int d,
                      const QuadricSegmenter::Params& p,
                      const std::vector<std::uint8_t>& taken = std::vector<std::uint8_t>());

}  // namespace quadric_slam
