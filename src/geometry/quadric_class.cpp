#include "quadric_slam/geometry/quadric_class.h"

#include <stdexcept>

namespace quadric_slam {

std::string toString(QuadricClass quadric_class) {
  switch (quadric_class) {
    case QuadricClass::kPlane:
      return "plane";
    case QuadricClass::kSphere:
      return "sphere";
    case QuadricClass::kCylinder:
      return "cylinder";
    case QuadricClass::kCone:
      return "cone";
    case QuadricClass::kGeneral:
      return "general";
  }
  throw std::invalid_argument("toString: invalid QuadricClass value " +
                              std::to_string(static_cast<int>(quadric_class)));
}

QuadricClass quadricClassFromString(const std::string& name) {
  for (QuadricClass c : kAllQuadricClasses) {
    if (toString(c) == name)
      return c;
  }
  throw std::invalid_argument("unknown quadric class '" + name +
                              "' (expected plane, sphere, cylinder, cone or general)");
}

QuadricClass quadricClassFromInt(int value) {
  if (value < 0 || value >= static_cast<int>(kAllQuadricClasses.size())) {
    throw std::invalid_argument("quadric class value " + std::to_string(value) +
                                " out of range [0, 4]");
  }
  return static_cast<QuadricClass>(value);
}

Eigen::Vector4d defaultSignature(QuadricClass quadric_class) {
  switch (quadric_class) {
    case QuadricClass::kPlane:
      return {1, 0, 0, 0};
    case QuadricClass::kSphere:
    case QuadricClass::kGeneral:
      return {1, 1, 1, -1};
    case QuadricClass::kCylinder:
      return {1, 1, 0, -1};  // permuted so the axis is the quadric z axis (Table II note)
    case QuadricClass::kCone:
      return {1, 1, -1, 0};
  }
  throw std::invalid_argument("defaultSignature: invalid QuadricClass");
}

int minimalDimension(QuadricClass quadric_class) {
  switch (quadric_class) {
    case QuadricClass::kPlane:
      return 3;
    case QuadricClass::kSphere:
      return 4;
    case QuadricClass::kCylinder:
      return 5;
    case QuadricClass::kCone:
      return 6;
    case QuadricClass::kGeneral:
      return 9;
  }
  throw std::invalid_argument("minimalDimension: invalid QuadricClass");
}

}  // namespace quadric_slam
