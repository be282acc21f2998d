// Planes grown over cells of the image grid rather than pixels, after CAPE (Proenca and Gao, "Fast
// Cylinder and Plane Extraction from Depth Cameras for Visual Odometry", IROS 2018).
//
// Beyond about 3 m a Kinect's depth noise (centimetres, in disparity steps) makes per-pixel
// normals too noisy to grow a wall or floor pixel by pixel: it comes out in fragments or not at
// all. A square cell of cell_size x cell_size pixels averages that noise: its plane is far
// steadier than any pixel normal, and its RMS says whether it is flat within the sensor's noise.
//  1. Each cell with at least half its pixels valid and free, no depth jump between neighbouring
//     pixels and a mean depth of at least cell_min_depth (nearer, pixel normals do better) gets
//     the plane fitted to its inverse depths (the sensor measures disparity; a PCA plane tips over
//     when the noise exceeds the cell's width); it is planar when the fit's RMS is within
//     merge_rms_factor x the expected noise at its depth and it is not seen at a grazing angle.
//  2. Planar cells grow into regions over their 4-neighbours, the flattest cells (RMS against the
//     noise) seeding first. A cell joins when its normal agrees with the region's within
//     max_normal_angle, or within noise_sigmas x the two normals' noise (up to twice
//     max_normal_angle), and its centroid lies within noise_sigmas x its own noise (plus the
//     sensor's bend) of the region's plane. The region's plane is refitted from the summed moments
//     of its cells. Regions of fewer than 4 cells are left to the pixels.
//  3. A region's pixels are the valid free pixels of its cells within the growing threshold of its
//     plane (planePointThreshold) whose normal is within 60 deg of the plane's (a crease's other
//     surface stays out; far pixel normals fail any tighter test). A region is kept when it holds at
//     least min_fragment_points of them and is flat (patchCurvature <= max_curvature: a large
//     cylinder's cells can chain into a region); then its pixels are marked used.
// The regions are fragments in the grower's sense: PlaneRegionGrower merges them with coplanar
// pixel-grown regions, drops what stays below min_points and fills their borders pixel by pixel.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <vector>

#include "quadric_slam/frontend/plane_region_grower.h"

namespace quadric_slam {

// valid[i]: point i may be used; used[i]: already taken (skipped), set for the returned regions'
// pixels. Returns no regions when params.cell_size < 2.
std::vector<PlaneRegionGrower::Region> growPlaneCells(
    const pcl::PointCloud<pcl::PointNormal>& cloud, const std::vector<std::uint8_t>& valid,
    std::vector<std::uint8_t>& used, const PlaneRegionGrower::Params& params);

}  // namespace quadric_slam
