// The reconstruction (mapping/reconstruction.h: landmark points projected onto their surfaces,
// label = landmark id) as a sensor_msgs/PointCloud2 for rviz and for the saved PCD file: fields
// x y z (float32, m), rgb (float32 holding 0xAARRGGBB, PCL's packing: rviz's RGB8 colour
// transformer reads it) and label (uint32, the landmark id). A point with a colour from the RGB
// image (rgba alpha != 0, frontend/support_colours.h) keeps it, with alpha 255; the others are
// coloured per landmark with landmarkColour(id) (ros/markers.h, the same colour as the landmark's
// marker), alpha 0, so a saved and reloaded cloud (ros/map_files.h) tells the two apart.
// Unorganized (height 1), dense.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>

namespace quadric_slam {

sensor_msgs::PointCloud2 reconstructionCloudMsg(const pcl::PointCloud<pcl::PointXYZRGBL>& points,
                                                const std_msgs::Header& header);

}  // namespace quadric_slam
