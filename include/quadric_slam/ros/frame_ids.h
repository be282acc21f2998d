// Frame ids as tf2 and rviz accept them. ROS 1 once allowed a leading '/' (the tf_prefix era) and
// TUM RGB-D rosbags still use it: images stamped "/openni_rgb_optical_frame", tf "/world" ->
// "/kinect" -> ... . tf2 drops the slash when it stores a transform but refuses to look one up
// for "/world", so rviz cannot place a message stamped with it. Every frame id we read from a
// message or a parameter goes through withoutLeadingSlash() before it is used in a tf lookup, a
// comparison or an outgoing header.
#pragma once

#include <string>

#include "quadric_slam/io/param_reader.h"

namespace quadric_slam {

// "/world" -> "world" (every leading '/' goes; tf2 refuses "//world" too); "world" and ""
// unchanged.
std::string withoutLeadingSlash(const std::string& frame_id);

// Whether two frame ids name the same tf frame (equal once both are without a leading '/').
bool sameFrame(const std::string& a, const std::string& b);

// The frame id to stamp on an output computed from an input in input_frame_id: `configured` when
// it is set, else the input's; either without a leading '/'.
std::string outputFrameId(const std::string& configured, const std::string& input_frame_id);

// readParam() for a frame id: reads key into frame_id (keeping the default when absent) without a
// leading '/', and records that effective value.
void readFrameParam(const ParamReader& reader, const std::string& key, std::string& frame_id,
                    ParamLog& log);

}  // namespace quadric_slam
