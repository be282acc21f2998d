// The latest colour images of a camera registered to the depth camera, for the mapping nodelet to
// colour the supporting points of the observations of the same instant
// (frontend/support_colours.h). Images arrive before the observations made from the depth image of
// the same instant (those wait for normals and segmentation), so each observation array looks its
// image up here by nearest stamp within a gate (TUM's associate.py rule, |difference| <
// max_difference) instead of a synchroniser: a frame without a matching image is still mapped,
// uncoloured, and never dropped.
#pragma once

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cstddef>
#include <deque>
#include <mutex>
#include <string>

#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {

// The image as CV_8UC3 in R G B order: rgb8 shares the message's data (no copy), bgr8 and mono8
// are converted (cv_bridge). Returns the problem (colourImageProblem() of message_validation.h, or
// cv_bridge's) and leaves *out empty when the image cannot be used.
std::string colourImageToRgb(const sensor_msgs::ImageConstPtr& image,
                             cv_bridge::CvImageConstPtr* out);

class ColourImageBuffer {
 public:
  struct Entry {
    double stamp = 0.0;              // s, of the image
    cv_bridge::CvImageConstPtr rgb;  // CV_8UC3, R G B
    CameraIntrinsics intrinsics;     // of the colour camera (its camera_info)
  };

  // capacity: images kept (the oldest go first), >= 1; max_difference: the stamp gate (s, > 0).
  // Throws std::invalid_argument naming the bad argument.
  ColourImageBuffer(std::size_t capacity, double max_difference);

  // Keeps the entry; an entry older than the newest one means time went backwards (a looping bag):
  // the buffer is cleared first.
  void add(Entry entry);
  // The entry nearest to stamp when within the gate; false otherwise (*out untouched).
  bool nearest(double stamp, Entry* out) const;
  // Forgets the images older than stamp (observations come in stamp order: an image older than
  // the latest observation's stamp minus the gate can no longer match).
  void dropBefore(double stamp);
  // Stamps of the oldest and newest image (s); false when empty.
  bool span(double* oldest, double* newest) const;
  void clear();
  std::size_t size() const;

 private:
  std::size_t capacity_;
  double max_difference_;
  mutable std::mutex mutex_;   // images arrive on one callback thread, observations on another
  std::deque<Entry> entries_;  // in stamp order
};

// The buffer entry of a colour image and its camera_info (image_transport's subscribeCamera
// pair): empty when usable, else the problem (the camera_info's, the image's as
// colourImageToRgb() says, or their sizes differing); *entry is filled only when usable.
std::string colourEntryFromMessages(const sensor_msgs::ImageConstPtr& image,
                                    const sensor_msgs::CameraInfoConstPtr& info,
                                    ColourImageBuffer::Entry* entry);

}  // namespace quadric_slam
