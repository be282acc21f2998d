#include "quadric_slam/ros/frame_ids.h"

namespace quadric_slam {

std::string withoutLeadingSlash(const std::string& frame_id) {
  const std::size_t first = frame_id.find_first_not_of('/');
  return first == std::string::npos ? std::string() : frame_id.substr(first);
}

bool sameFrame(const std::string& a, const std::string& b) {
  return withoutLeadingSlash(a) == withoutLeadingSlash(b);
}

std::string outputFrameId(const std::string& configured, const std::string& input_frame_id) {
  return withoutLeadingSlash(configured.empty() ? input_frame_id : configured);
}

void readFrameParam(const ParamReader& reader, const std::string& key, std::string& frame_id,
                    ParamLog& log) {
  reader.get(key, frame_id);
  frame_id = withoutLeadingSlash(frame_id);
  log.add(key, frame_id);
}

}  // namespace quadric_slam
