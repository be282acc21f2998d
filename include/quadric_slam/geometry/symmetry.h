// Symmetry handling for the quadric classes: the measured quadric frame is only defined up to the
// class's symmetry group (a sphere's rotation, a cylinder's rotation about and slide along its
// axis, a cone's rotation about its axis, a plane's in-plane motions, plus discrete axis flips).
// Before taking [-] we replace the measurement z by the member z G of its symmetry orbit that is
// closest to the prediction h, defined exactly as: the dropped tangent components (the symmetry
// generators, quadric_classes.h) of e = log((z G)^-1 h)^vee are zero, and the flip brings the
// symmetry axis of z G to the same side as h's (positive dot product). The residual B^+ [e; ds]
// is then a function of the two surfaces only, not of the frames chosen to describe them.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {

// Given D = T_ZH (the prediction's frame in the measured quadric frame, z^-1 h), returns the
// symmetry element G (in the measured quadric frame) with the properties above. For kGeneral this
// picks among the four axis half-turns only (see the overload taking the quadric).
Eigen::Isometry3d symmetryAlignment(QuadricClass quadric_class, const Eigen::Isometry3d& T_z_h);

// A general quadric's frame is defined up to more than the half-turns: any rotation that permutes
// its axes (a signed permutation matrix, det +1) and maps each axis onto one with the same
// signature entry describes the same surface once the scale entries follow their axes
// (S' = |P|^T S, with |P| the entry-wise absolute value). E.g. an ellipsoid has 24 such frames
// (the semi-axes in any order), a hyperboloid of one sheet 8 (its two +1 axes may swap); other
// signatures keep the 4 half-turns. Returns them, the identity first.
std::vector<Eigen::Matrix3d> generalAxisRelabellings(const Eigen::Vector4d& signature);
// symmetryAlignment for the quadric z itself: for kGeneral the relabelling (above) whose rotation
// is closest to that of T_z_h (largest trace of P^T R_D); for the other classes the class's own.
Eigen::Isometry3d symmetryAlignment(const QuadricModel& z, const Eigen::Isometry3d& T_z_h);
// z re-expressed in the frame z G, G a symmetry element of its class (for kGeneral a relabelling:
// the scale entries follow the axes). Same surface.
QuadricModel withSymmetry(const QuadricModel& z, const Eigen::Isometry3d& G);

// Jacobian of e = log(G(D)^-1 D)^vee w.r.t. a body perturbation D -> D exp(delta^), with G
// following the perturbation so that the dropped components stay zero (implicit function theorem):
//   de = (I - J_l^-1 P^T (P J_l^-1 P^T)^-1 P) J_r^-1 delta,   J_l, J_r at e, P = dropped rows.
Matrix6d alignedErrorJacobian(QuadricClass quadric_class, const Vector6d& e);
// The rate of the symmetry generator in that perturbation: G(D exp(delta^)) = G exp(gamma^) with
//   gamma = P^T (P J_l^-1 P^T)^-1 P J_r^-1 delta  (6 x 6, zero outside the dropped rows).
// alignedErrorJacobian = J_r^-1 - J_l^-1 * alignmentGeneratorRate.
Matrix6d alignmentGeneratorRate(QuadricClass quadric_class, const Vector6d& e);
// ad(xi) = [phi^, rho^; 0, phi^], the SE(3) adjoint of the Lie algebra: Ad(exp(xi^)) = exp(ad(xi)).
Matrix6d adSE3(const Vector6d& xi);

// How a class's minimal vector (and hence its covariance) transforms when the quadric frame is
// re-expressed by a symmetry element G: a perturbation nu of z is Ad(G^-1) nu for z G, so a minimal
// vector x of z becomes minimalAdjoint(G^-1) x and a covariance C becomes M C M^T (k x k,
// M = B^+ blockdiag(Ad_G, I) B; exact because each class's symmetries preserve its kept subspace).
// For kGeneral with G a relabelling (generalAxisRelabellings) the scale block is |R_G| instead of
// I: the scale perturbations follow their axes as the scales do.
Eigen::MatrixXd minimalAdjoint(QuadricClass quadric_class, const Eigen::Isometry3d& G);

// z re-expressed by the member of its symmetry orbit closest to `reference` (same surface).
QuadricModel alignToReference(const QuadricModel& z, const QuadricModel& reference);

// Surface difference in the class's minimal space: B^+ (a [-] alignToReference(b, a)).
// Zero whenever a and b describe the same surface.
Eigen::VectorXd surfaceMinus(const QuadricModel& a, const QuadricModel& b);

}  // namespace quadric_slam
