// Completion of a segmentation's labels at surface boundaries. The normal estimator gives no normal
// to points within a few pixels of a depth edge or a hole (their smoothing window would straddle
// it), so the segmenter, which needs normals, leaves an unlabelled rim around every segment; on a
// small object seen in front of a background that rim is a large part of it. Here a point with
// depth but without a normal, next to a labelled pixel, joins that detection when it fits the
// surface as well as the segment's own points do: within rms_multiple x the fit's RMS (and the
// segmenter's distance threshold), so the mixed-depth "flying pixels" of a depth edge stay out. The
// closest surface wins when several border the point; growth is ring by ring, a few pixels out.
// Points that have a normal were judged by the segmenter and are left as they are.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "quadric_slam/frontend/quadric_segmenter.h"

namespace quadric_slam {

struct BoundaryCompletion {
  int rings = 3;           // how many pixels out from the labelled points, >= 0 (0 = off)
  double min_range = 0.3;  // m: points outside [min_range, max_range] are never labelled
  double max_range = 4.5;
  double distance_factor = 0.008;  // threshold max(min_distance, distance_factor * z^2) (1/m, m)
  double min_distance = 0.006;
  double rms_multiple = 3.0;  // distance gate in RMS of the detection's fit (>= 1 mm)
};

// Adds the boundary points to segmentation.labels and to each detection's num_points, roi and
// extent box (its fit and covariance, from the points with normals, are unchanged).
void completeBoundaryLabels(const pcl::PointCloud<pcl::PointNormal>& cloud,
                            const BoundaryCompletion& settings, Segmentation& segmentation);

}  // namespace quadric_slam
