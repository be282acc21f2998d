#include "quadric_slam/frontend/frame.h"

#include <sstream>
#include <string>
#include <stdexcept>

namespace quadric_slam {

void BackProjectionParams::validate() const {
  if (decimation < 1 || decimation > 16) {
    throw std::invalid_argument("decimation must be in [1, 16], got " + std::to_string(decimation));
  }
  if (!(min_range >= 0.0)) {
    throw std::invalid_argument("min_range must be >= 0 m, got " + std::to_string(min_range));
  }
  if (!(max_range > min_range)) {
    throw std::invalid_argument("max_range must be > min_range (" + std::to_string(min_range) +
                                " m), got " + std::to_string(max_range));
  }
}

}  // namespace quadric_slam
