// A hand-held or robot-mounted camera moves at a bounded speed, so an odometry increment over dt
// seconds is never less certain than that speed allows, whatever the tracker reports. A tracker
// that lost the view, or that is degenerate along a direction (a single plane fills the view),
// reports a huge variance there (odometry.yaml degenerate_variance, 1 m^2 per frame); composed
// over a few frames, such an odometry factor lets the window's solve move the keyframe by metres
// along that direction on the pull of weakly constraining landmark observations. The bound keeps
// the factor as uncertain as the camera's motion can make it, and no more.
#pragma once

#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {

// The increment covariance (right perturbation, body [rho; phi]) bounded by the camera's motion
// over dt seconds: in the coordinates scaled by sigma_t = max_speed dt (translation) and
// sigma_r = max_angular_speed dt (rotation), every eigenvalue above 1 is clamped to 1. The result
// is no larger than `covariance` and no larger than diag(sigma_t^2 I, sigma_r^2 I) (Loewner order),
// and equals `covariance` when it is within the bound already. A non-positive dt or speed returns
// `covariance` unchanged (no bound).
Matrix6d boundIncrementCovariance(const Matrix6d& covariance, double dt, double max_speed,
                                  double max_angular_speed);

}  // namespace quadric_slam
