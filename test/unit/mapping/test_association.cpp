// QuadricAssociator: the right landmark among several of the same class, a far measurement
// refused, classes never mixed, the extent check (a second table top at the same height), the
// covariance floor that lets a 1 deg pose error through, one-to-one assignment.
#include <gtest/gtest.h>

#include <random>

#include "quadric_slam/mapping/association.h"
#include "synthetic_world.h"

namespace quadric_slam {
namespace {

AssociationTarget target(int id, const test::TrueLandmark& l) {
  return {id, l.quadric_world, Eigen::MatrixXd(), l.extent};
}

// A camera 2 m in front of the origin looking at it, and the same pose with the prediction error
// (1 deg about an oblique axis, 2 cm) that the gate must absorb.
const Eigen::Isometry3d kTrueCamera =
    test::lookAlong(Eigen::Vector3d(-2.0, 0.3, 1.0), Eigen::Vector3d(1.0, -0.15, -0.4));
Eigen::Isometry3d predictedCamera(double degrees = 1.0) {
  Vector6d xi;
  xi << 0.012, -0.01, 0.012, Eigen::Vector3d(1, 2, -1).normalized() * degrees * M_PI / 180;
  return plus(kTrueCamera, xi);
}

TEST(QuadricAssociator, ParamsValidate) {
  QuadricAssociator::Params p;
  EXPECT_NO_THROW(p.validate());
  p.gate_probability = 1.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.floor_rotation_sigma = -1;
  EXPECT_THROW(QuadricAssociator{p}, std::invalid_argument);
  p = {};
  p.max_range = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.extent_margin = -0.1;
  try {
    p.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("extent_margin"), std::string::npos) << e.what();
  }
}

TEST(QuadricAssociator, GateIsTheChiSquareQuantileOfTheMinimalDimension) {
  const QuadricAssociator associator;
  EXPECT_NEAR(associator.gate(QuadricClass::kPlane), 16.266, 1e-3);  // chi2_3(0.999)
  EXPECT_NEAR(associator.gate(QuadricClass::kSphere), 18.467, 1e-3);
  EXPECT_NEAR(associator.gate(QuadricClass::kCylinder), 20.515, 1e-3);
  EXPECT_NEAR(associator.gate(QuadricClass::kCone), 22.458, 1e-3);
  EXPECT_NEAR(associator.gate(QuadricClass::kGeneral), 27.877, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(1, 0.95), 3.8415, 1e-4);
  EXPECT_NEAR(chiSquareQuantile(2, 0.99), 9.2103, 1e-4);
  EXPECT_NEAR(chiSquareQuantile(9, 0.5), 8.3428, 1e-4);
  EXPECT_THROW(chiSquareQuantile(0, 0.5), std::invalid_argument);
}

// Several landmarks of each class a few decimetres apart; each measurement (noise as stated in
// synthetic_world.h) from the true pose, associated at a predicted pose 1 deg / 2 cm off, must
// find its own landmark.
TEST(QuadricAssociator, PicksTheRightLandmarkAmongSeveralOfTheSameClass) {
  const Eigen::Vector3d Z = Eigen::Vector3d::UnitZ(), X = Eigen::Vector3d::UnitX();
  const std::vector<test::TrueLandmark> world = {
      test::sphere(Eigen::Vector3d(0, -0.6, 0.3), 0.2),
      test::sphere(Eigen::Vector3d(0, 0, 0.3), 0.2),
      test::sphere(Eigen::Vector3d(0, 0.6, 0.3), 0.2),
      test::sphere(Eigen::Vector3d(0, 0, 0.3), 0.3),  // same centre, other radius
      test::cylinder(Eigen::Vector3d(0.3, -0.5, 0.5), Z, 0.1, 0.5),
      test::cylinder(Eigen::Vector3d(0.3, 0.0, 0.5), Z, 0.1, 0.5),
      test::cylinder(Eigen::Vector3d(0.3, 0.5, 0.5), Z, 0.1, 0.5),
      test::cone(Eigen::Vector3d(-0.2, -0.4, 0.8), -Z, 0.3, 0.5),
      test::cone(Eigen::Vector3d(-0.2, 0.4, 0.8), -Z, 0.3, 0.5),
      test::plane(Eigen::Vector3d(0, 0, 0), Z, X, 3, 3),
      test::plane(Eigen::Vector3d(0, 0, 0.4), Z, X, 3, 3),  // 40 cm above
      test::plane(Eigen::Vector3d(1.5, 0, 1), -X, Eigen::Vector3d::UnitY(), 3, 1),
  };
  std::vector<AssociationTarget> targets;
  for (size_t i = 0; i < world.size(); ++i)
    targets.push_back(target(static_cast<int>(i), world[i]));
  const QuadricAssociator associator;
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<QuadricMeasurement> measurements;
    for (const test::TrueLandmark& l : world)
      measurements.push_back(test::measure(l, kTrueCamera, rng));
    const std::vector<Association> a =
        associator.associate(measurements, predictedCamera(), Matrix6d::Zero(), targets);
    ASSERT_EQ(a.size(), world.size());
    for (size_t i = 0; i < world.size(); ++i) {
      EXPECT_EQ(a[i].outcome, AssociationOutcome::kMatched)
          << "trial " << trial << " landmark " << i;
      EXPECT_EQ(a[i].target_index, static_cast<int>(i))
          << "trial " << trial << " d2 " << a[i].squared_error;
    }
  }
}

TEST(QuadricAssociator, RejectsAMeasurementFarFromAllLandmarks) {
  const std::vector<test::TrueLandmark> world = {test::sphere(Eigen::Vector3d(0, -0.6, 0.3), 0.2),
                                                 test::sphere(Eigen::Vector3d(0, 0.6, 0.3), 0.2)};
  const std::vector<AssociationTarget> targets = {target(0, world[0]), target(1, world[1])};
  const QuadricAssociator associator;
  std::mt19937 rng(8);
  const test::TrueLandmark far = test::sphere(Eigen::Vector3d(0.2, 0.0, 1.2), 0.2);
  const std::vector<Association> a = associator.associate(
      {test::measure(far, kTrueCamera, rng)}, predictedCamera(), Matrix6d::Zero(), targets);
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kOutsideGate);
  EXPECT_EQ(a[0].target_index, -1);
  EXPECT_GT(a[0].squared_error, associator.gate(QuadricClass::kSphere));
}

// A cylinder measured exactly where a sphere landmark of the same radius stands, and a sphere
// where a cylinder stands: never matched across classes.
TEST(QuadricAssociator, ClassesNeverMix) {
  const test::TrueLandmark sphere = test::sphere(Eigen::Vector3d(0, 0, 0.3), 0.2);
  const test::TrueLandmark cylinder =
      test::cylinder(Eigen::Vector3d(0, 0, 0.3), Eigen::Vector3d::UnitZ(), 0.2, 0.2);
  const QuadricAssociator associator;
  std::mt19937 rng(9);
  std::vector<Association> a =
      associator.associate({test::measure(cylinder, kTrueCamera, rng)}, kTrueCamera,
                           Matrix6d::Zero(), {target(0, sphere)});
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kNoTargetOfClass);
  a = associator.associate({test::measure(sphere, kTrueCamera, rng)}, kTrueCamera, Matrix6d::Zero(),
                           {target(0, cylinder)});
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kNoTargetOfClass);
  // With both present each goes to its own class.
  a = associator.associate(
      {test::measure(cylinder, kTrueCamera, rng), test::measure(sphere, kTrueCamera, rng)},
      kTrueCamera, Matrix6d::Zero(), {target(0, sphere), target(1, cylinder)});
  EXPECT_EQ(a[0].target_index, 1);
  EXPECT_EQ(a[1].target_index, 0);
  EXPECT_THROW(associator.squaredError(test::measure(cylinder, kTrueCamera, rng), kTrueCamera,
                                       Matrix6d::Zero(), target(0, sphere)),
               std::invalid_argument);
}

// General quadrics match only quadrics of the same signature (an ellipsoid is never a hyperboloid).
TEST(QuadricAssociator, GeneralQuadricsNeedTheSameSignature) {
  const Eigen::Isometry3d T = makeIsometry(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0.5));
  const QuadricModel ellipsoid(QuadricClass::kGeneral, T, Eigen::Vector3d(4, 3, 2),
                               Eigen::Vector4d(1, 1, 1, -1));
  const QuadricModel hyperboloid(QuadricClass::kGeneral, T, Eigen::Vector3d(4, 3, 2),
                                 Eigen::Vector4d(1, 1, -1, -1));
  QuadricMeasurement m;
  m.quadric_camera = predictMeasurement(kTrueCamera, ellipsoid);
  m.covariance = 1e-4 * Eigen::MatrixXd::Identity(9, 9);
  const QuadricAssociator associator;
  std::vector<Association> a = associator.associate(
      {m}, kTrueCamera, Matrix6d::Zero(), {{0, hyperboloid, Eigen::MatrixXd(), ExtentBox{}}});
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kNoTargetOfClass);
  a = associator.associate({m}, kTrueCamera, Matrix6d::Zero(),
                           {{0, hyperboloid, Eigen::MatrixXd(), ExtentBox{}},
                            {1, ellipsoid, Eigen::MatrixXd(), ExtentBox{}}});
  EXPECT_EQ(a[0].target_index, 1);
  EXPECT_LT(a[0].squared_error, 1e-6);
}

// Two table tops at the same height are one infinite plane; only the extents tell them apart.
TEST(QuadricAssociator, ExtentSeparatesTwoTablesAtTheSameHeight) {
  const Eigen::Vector3d Z = Eigen::Vector3d::UnitZ(), X = Eigen::Vector3d::UnitX();
  const test::TrueLandmark desk = test::plane(Eigen::Vector3d(0, -0.8, 0.75), Z, X, 0.4, 0.3);
  const test::TrueLandmark table = test::plane(Eigen::Vector3d(0, 0.8, 0.75), Z, X, 0.4, 0.3);
  const QuadricAssociator associator;
  std::mt19937 rng(10);
  const QuadricMeasurement of_table = test::measure(table, kTrueCamera, rng);
  // The table is inside the desk's chi-square gate (same plane) ...
  EXPECT_LT(associator.squaredError(of_table, predictedCamera(), Matrix6d::Zero(), target(0, desk)),
            associator.gate(QuadricClass::kPlane));
  // ... but its points are 1 m away from the desk's, so it is refused ...
  std::vector<Association> a =
      associator.associate({of_table}, predictedCamera(), Matrix6d::Zero(), {target(0, desk)});
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kNoOverlap);
  // ... and goes to the table when the table is known.
  a = associator.associate({of_table}, predictedCamera(), Matrix6d::Zero(),
                           {target(0, desk), target(1, table)});
  EXPECT_EQ(a[0].target_index, 1);
  // Without the extent check it would take the desk.
  QuadricAssociator::Params p;
  p.check_extent = false;
  a = QuadricAssociator(p).associate({of_table}, predictedCamera(), Matrix6d::Zero(),
                                     {target(0, desk)});
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kMatched);
}

// Fit covariances from thousands of points are tiny: without the floors a 1 deg pose error fails
// the gate; with the default floors it passes, and the prediction covariance widens the gate too.
TEST(QuadricAssociator, FloorAbsorbsPosePredictionError) {
  const test::TrueLandmark cylinder =
      test::cylinder(Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d::UnitZ(), 0.15, 0.5);
  std::mt19937 rng(11);
  QuadricMeasurement m = test::measure(cylinder, kTrueCamera, rng, 0.0);
  m.covariance *= 1e-4;  // sub-mm, sub-0.03 deg: what a fit from thousands of points reports
  QuadricAssociator::Params none;
  none.floor_translation_sigma = none.floor_rotation_sigma = none.floor_scale_fraction = 0;
  none.pose_translation_sigma = none.pose_rotation_sigma = 0;
  const QuadricAssociator bare(none), floored;
  const double gate = floored.gate(QuadricClass::kCylinder);
  const double d2_bare =
      bare.squaredError(m, predictedCamera(), Matrix6d::Zero(), target(0, cylinder));
  const double d2_floored =
      floored.squaredError(m, predictedCamera(), Matrix6d::Zero(), target(0, cylinder));
  std::cout << "1 deg / 2 cm pose error: d2 without floor " << d2_bare << ", with floor "
            << d2_floored << ", gate " << gate << "\n";
  EXPECT_GT(d2_bare, gate);
  EXPECT_LT(d2_floored, gate);
  // A 10 deg error fails the default floor, but passes when the caller reports that uncertainty.
  const double d2_5deg =
      floored.squaredError(m, predictedCamera(10.0), Matrix6d::Zero(), target(0, cylinder));
  Matrix6d P = Matrix6d::Zero();
  P.diagonal() << 0.02 * 0.02, 0.02 * 0.02, 0.02 * 0.02, 0.1 * 0.1, 0.1 * 0.1, 0.1 * 0.1;
  const double d2_5deg_with_p =
      floored.squaredError(m, predictedCamera(10.0), P, target(0, cylinder));
  EXPECT_GT(d2_5deg, gate);
  EXPECT_LT(d2_5deg_with_p, gate);
  // With the measurement at the truth and the true pose, d2 is ~0.
  EXPECT_LT(floored.squaredError(m, kTrueCamera, Matrix6d::Zero(), target(0, cylinder)), 1e-6);
}

// Landmarks beyond max_range (their boxes) are not even compared; targets of unknown extent are.
TEST(QuadricAssociator, FarTargetsAreNotCompared) {
  const test::TrueLandmark s = test::sphere(Eigen::Vector3d(0, 0, 0.3), 0.2);
  std::mt19937 rng(13);
  const QuadricMeasurement m = test::measure(s, kTrueCamera, rng);
  QuadricAssociator::Params p;
  p.max_range = 1.5;  // the sphere's box is ~2 m from the camera
  std::vector<Association> a =
      QuadricAssociator(p).associate({m}, kTrueCamera, Matrix6d::Zero(), {target(0, s)});
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kNoTargetOfClass);
  AssociationTarget unknown_extent = target(0, s);
  unknown_extent.extent = ExtentBox{};
  a = QuadricAssociator(p).associate({m}, kTrueCamera, Matrix6d::Zero(), {unknown_extent});
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kMatched);
  p.max_range = 3.0;
  a = QuadricAssociator(p).associate({m}, kTrueCamera, Matrix6d::Zero(), {target(0, s)});
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kMatched);
}

TEST(QuadricAssociator, OneToOne) {
  const test::TrueLandmark s = test::sphere(Eigen::Vector3d(0, 0, 0.3), 0.2);
  std::mt19937 rng(12);
  const QuadricAssociator associator;
  const QuadricMeasurement exact = test::measure(s, kTrueCamera, rng, 0.0);
  const QuadricMeasurement noisy = test::measure(s, kTrueCamera, rng, 3.0);
  const std::vector<Association> a =
      associator.associate({noisy, exact}, kTrueCamera, Matrix6d::Zero(), {target(0, s)});
  EXPECT_EQ(a[1].outcome, AssociationOutcome::kMatched);
  EXPECT_EQ(a[0].outcome, AssociationOutcome::kTakenByBetter);
}

// The correlated-noise scaling of the gate (correlated_noise_fraction) widens curved surfaces'
// gates, by more for a larger support; a plane's and a general quadric's covariance stay as measured.
TEST(QuadricAssociator, CorrelatedNoiseScalesCurvedSurfacesOnly) {
  std::mt19937 rng(12);
  const QuadricAssociator associator;
  const test::TrueLandmark cylinder =
      test::cylinder(Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d::UnitZ(), 0.15, 0.5);
  QuadricMeasurement m = test::measure(cylinder, kTrueCamera, rng);
  const double factor = associator.correlatedNoiseFactor(m);
  EXPECT_GT(factor, 1.5);
  m.num_points *= 4;  // the same area with more points: more points per correlation cell
  EXPECT_GT(associator.correlatedNoiseFactor(m), factor);
  QuadricAssociator::Params independent;
  independent.correlated_noise_fraction = 0.0;
  EXPECT_EQ(QuadricAssociator(independent).correlatedNoiseFactor(m), 1.0);

  const test::TrueLandmark wall = test::plane(Eigen::Vector3d(0, 0.8, 0.75),
                                              Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX(), 1.0, 1.0);
  const QuadricMeasurement of_wall = test::measure(wall, kTrueCamera, rng);
  EXPECT_EQ(associator.correlatedNoiseFactor(of_wall), 1.0);
  EXPECT_TRUE(associator.associationCovariance(of_wall).isApprox(of_wall.covariance));
}

}  // namespace
}  // namespace quadric_slam
