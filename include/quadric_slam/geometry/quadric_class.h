// The quadric classes the system knows and the facts that are fixed per class: the signature
// (the paper's eq. 5) and the dimension of the minimal parameterisation (Table II).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

namespace quadric_slam {

// Values match the CLASS_* constants of msg/QuadricSurface.msg.
enum class QuadricClass : int { kPlane = 0, kSphere = 1, kCylinder = 2, kCone = 3, kGeneral = 4 };

constexpr std::array<QuadricClass, 5> kAllQuadricClasses = {
    QuadricClass::kPlane, QuadricClass::kSphere, QuadricClass::kCylinder, QuadricClass::kCone,
    QuadricClass::kGeneral};

// Lower-case name used in YAML files and logs: plane, sphere, cylinder, cone, general.
std::string toString(QuadricClass quadric_class);
// Inverse of toString(); throws std::invalid_argument for an unknown name.
QuadricClass quadricClassFromString(const std::string& name);
// Inverse of static_cast<int>(); throws std::invalid_argument when out of range.
QuadricClass quadricClassFromInt(int value);

// Signature sigma of the class (eq. 5; Table II for the classes of revolution). For kGeneral the
// signature is per quadric; this returns the ellipsoid's (+1, +1, +1, -1).
Eigen::Vector4d defaultSignature(QuadricClass quadric_class);

// Dimension of the class's minimal parameterisation (Table II): 3, 4, 5, 6 or 9.
int minimalDimension(QuadricClass quadric_class);

}  // namespace quadric_slam
