// A real depth image seen from a moved camera: the measured surface is re-projected into the new
// view, with the occlusions and holes a real camera would see there. Used to test odometry on real
// sensor data under known motions of any size (src/tools/warp_odometry_bench.cpp).
//
// The depth image is treated as a surface: every 2 x 2 block of valid pixels gives two triangles,
// except where the depth jumps between neighbours (an occluding edge: the surface is not
// continuous there). The triangles are rasterised into the moved camera with a z-buffer, depth
// interpolated linearly in 1/z (exact for a planar triangle under perspective). So
//   - a surface hidden behind a nearer one stays hidden (z-buffer),
//   - what the original camera did not see (behind an occluding edge, outside its image, its own
//     holes) is a hole (NaN) in the new view: nothing is filled in,
//   - a surface seen closer up is not torn into a dotted pattern (forward splatting of single
//     pixels would leave gaps through which farther surfaces leak).
// The depth noise moves with the surface it was measured on; no new noise is added.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {

struct DepthWarpParams {
  // Two neighbouring pixels belong to one continuous surface when their depths differ by at most
  // max(min_depth_jump, depth_jump_fraction * the nearer depth). A Kinect v1's disparity step at
  // 4 m is about 3% of the depth, and a plane seen at 80 degrees from its normal changes depth by
  // about 1-2% per pixel: 5% keeps such surfaces whole and cuts object edges. (0, 1]
  double depth_jump_fraction = 0.05;
  double min_depth_jump = 0.02;  // m, > 0
  double min_depth = 0.05;       // m, surface in front of this (in the moved camera) is dropped, > 0

  // Throws std::invalid_argument naming the bad field and its range.
  void validate() const;
};

// depth_m: CV_32FC1 metres, NaN or <= 0 = no data, of the size intrinsics.width x height.
// T_reference_moved: pose of the moved camera in the reference (original) camera's frame.
// Returns the moved camera's CV_32FC1 depth image (z in its optical frame, metres, NaN = hole),
// same size and intrinsics. Throws std::invalid_argument when the image does not fit.
cv::Mat warpDepthImage(const cv::Mat& depth_m, const CameraIntrinsics& intrinsics,
                       const Eigen::Isometry3d& T_reference_moved,
                       const DepthWarpParams& params = DepthWarpParams());

}  // namespace quadric_slam
