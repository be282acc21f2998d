// Cylinder <-> cone association (mapping/association_cross_class.h): a band of a cone fitted as a
// cylinder (and a slender cylinder fitted as a cone) is counted on the landmark of the other class
// without a factor, so one surface stays one landmark whichever class a frame's fit chose; a
// cylinder on the cone's axis (a lamp post inside its shade) or around it a few cm out stays a
// landmark of its own.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/geometry/surface_distance.h"
#include "quadric_slam/mapping/association_cross_class.h"
#include "quadric_slam/mapping/landmark_registry.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "synthetic_world.h"

namespace quadric_slam {
namespace {

const Eigen::Isometry3d kCamera =
    test::lookAlong(Eigen::Vector3d(-2.0, 0.0, 1.0), Eigen::Vector3d(1.0, 0.0, -0.4));

// A lamp-shade-like cone: apex above, opening downwards, half-angle 0.45 rad, surface from 0.05 to
// 0.4 m below the apex.
const Eigen::Vector3d kApex(0.3, 0.5, 1.2);
const Eigen::Vector3d kAxis = -Eigen::Vector3d::UnitZ();
constexpr double kHalfAngle = 0.45;
test::TrueLandmark shade() {
  return test::cone(kApex, kAxis, kHalfAngle, 0.4);
}

// The cylinder through a band of that cone from s0 to s1 along the axis: coaxial, the cone's
// radius at the band's middle, the band's height (what a cylinder fit of the band returns).
test::TrueLandmark bandAsCylinder(double s0, double s1, double radius_offset = 0.0) {
  const double s_mid = 0.5 * (s0 + s1);
  return test::cylinder(kApex + s_mid * kAxis, kAxis, s_mid * std::tan(kHalfAngle) + radius_offset,
                        0.5 * (s1 - s0));
}

// Maps the cone from five frames that see it alone; returns its landmark's id.
int mapTheCone(LandmarkRegistry& map, std::mt19937& rng) {
  for (int frame = 1; frame <= 5; ++frame)
    map.integrate(frame, 0.1 * frame, {test::measure(shade(), kCamera, rng)}, kCamera,
                  Matrix6d::Zero());
  EXPECT_EQ(map.landmarks().size(), 1u);
  return map.landmarks().empty() ? -1 : map.landmarks().begin()->first;
}

// The landmark's surface distance (geometry/surface_distance.h, points in the parent frame) on a
// cone's double nappe, as the cross-class test uses it.
TEST(CrossClass, SurfaceDistanceOfACone) {
  const QuadricModel cone = quadricFromShape(ConeShape{Eigen::Vector3d::Zero(), kAxis, 0.45});
  // Points given in the cone's own frame, where the opening is along +z.
  auto distance = [&](const Eigen::Vector3d& p_cone) {
    return surfaceDistance(cone, cone.pose() * p_cone);
  };
  const double r = 0.3 * std::tan(0.45);
  EXPECT_NEAR(distance(Eigen::Vector3d(r, 0, 0.3)), 0.0, 1e-12);
  // 1 cm outside radially: cos(half-angle) cm from the nappe.
  EXPECT_NEAR(distance(Eigen::Vector3d(0, r + 0.01, 0.3)), 0.01 * std::cos(0.45), 1e-12);
  // On the axis: sin(half-angle) times the distance to the apex, on either side of it (the quadric
  // is the double cone; a frame flipped by a symmetry names the other nappe).
  EXPECT_NEAR(distance(Eigen::Vector3d(0, 0, -0.2)), 0.2 * std::sin(0.45), 1e-12);
  EXPECT_NEAR(distance(Eigen::Vector3d(-r, 0, -0.3)), 0.0, 1e-12);
  const QuadricModel cylinder =
      quadricFromShape(CylinderShape{Eigen::Vector3d::Zero(), kAxis, 0.1});
  EXPECT_NEAR(surfaceDistance(cylinder, cylinder.pose() * Eigen::Vector3d(0.13, 0, 5.0)), 0.03,
              1e-12);
}

// A coaxial cylinder at the band's middle radius departs from the cone by |t| sin(half-angle) at
// height t from the middle: RMS over a band of height h is h sin(half-angle) / sqrt(12).
TEST(CrossClass, CylinderOfAConeBandIsWithinItsSlope) {
  const QuadricModel cone = shade().quadric_world;
  for (double h : {0.05, 0.1, 0.2}) {
    const test::TrueLandmark band = bandAsCylinder(0.25 - 0.5 * h, 0.25 + 0.5 * h);
    const double expected = h * std::sin(kHalfAngle) / std::sqrt(12.0);
    EXPECT_NEAR(crossClassDistance(band.quadric_world, band.extent, cone), expected,
                0.02 * expected)
        << "band height " << h;
    // The same from the other side: the cone band measured against the cylinder.
    const double s0 = 0.25 - 0.5 * h, s1 = 0.25 + 0.5 * h, r1 = s1 * std::tan(kHalfAngle);
    const ExtentBox cone_band{Eigen::Vector3d(-r1, -r1, s0), Eigen::Vector3d(r1, r1, s1)};
    // (Measured radially to the cylinder: 1 / cos(half-angle) times the above.)
    EXPECT_NEAR(crossClassDistance(cone, cone_band, band.quadric_world),
                expected / std::cos(kHalfAngle), 0.02 * expected);
  }
  // A sleeve 4 cm outside the band: cos(half-angle) 4 cm away.
  const test::TrueLandmark sleeve = bandAsCylinder(0.2, 0.3, 0.04);
  EXPECT_GT(crossClassDistance(sleeve.quadric_world, sleeve.extent, cone), 0.035);
  // Within a class the surfaces are compared too (a partial view against its landmark); a plane
  // never, and no box means no comparison.
  EXPECT_NEAR(crossClassDistance(cone, shade().extent, cone), 0.0, 1e-9);
  const QuadricModel floor = quadricFromShape(PlaneShape{Eigen::Vector3d::UnitZ(), 0.0});
  EXPECT_TRUE(std::isinf(crossClassDistance(floor, shade().extent, floor)));
  EXPECT_TRUE(std::isinf(crossClassDistance(sleeve.quadric_world, ExtentBox{}, cone)));
}

TEST(CrossClass, ParamIsValidated) {
  QuadricAssociator::Params p;
  p.cross_class_distance = -0.01;
  try {
    p.validate();
    ADD_FAILURE() << "a negative cross_class_distance was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cross_class_distance"), std::string::npos) << e.what();
  }
}

// A cone landmark, then frames that see the cone and, as a second measurement, a band of it
// fitted as a cylinder: one landmark (the cone) that counts both, no cylinder candidate.
TEST(CrossClass, CylinderObservationsOfAConeBandCountOnTheCone) {
  LandmarkRegistry map;
  std::mt19937 rng(5);
  const int cone_id = mapTheCone(map, rng);
  ASSERT_EQ(map.landmarks().size(), 1u);
  for (int frame = 6; frame <= 25; ++frame) {
    const MapUpdate u = map.integrate(frame, 0.1 * frame,
                                      {test::measure(shade(), kCamera, rng),
                                       test::measure(bandAsCylinder(0.2, 0.3), kCamera, rng)},
                                      kCamera, Matrix6d::Zero());
    EXPECT_EQ(u.measurements[0].fate, MeasurementFate::kLandmark);
    EXPECT_FALSE(u.measurements[0].without_factor);
    EXPECT_EQ(u.measurements[1].fate, MeasurementFate::kLandmark) << "frame " << frame;
    EXPECT_EQ(u.measurements[1].id, cone_id);
    EXPECT_TRUE(u.measurements[1].without_factor);
  }
  EXPECT_EQ(map.landmarks().size(), 1u);
  EXPECT_TRUE(map.candidates().empty());
  EXPECT_EQ(map.landmark(cone_id).observations, 5 + 2 * 20);
}

// With the test off (cross_class_distance 0) the same frames make a cylinder landmark beside the
// cone: the case above is decided by the cross-class test, not by the gate.
TEST(CrossClass, OffMakesTwoLandmarks) {
  LandmarkRegistry::Params params;
  params.association.cross_class_distance = 0.0;
  LandmarkRegistry map(params);
  std::mt19937 rng(5);
  for (int frame = 1; frame <= 12; ++frame)
    map.integrate(frame, 0.1 * frame,
                  {test::measure(shade(), kCamera, rng),
                   test::measure(bandAsCylinder(0.2, 0.3), kCamera, rng)},
                  kCamera, Matrix6d::Zero());
  EXPECT_EQ(map.landmarks().size(), 2u);
}

// Both seen from the first frame: the cylinder's candidate reaches five observations in the frame
// the cone's is promoted, and is absorbed by the new cone landmark instead of becoming a landmark.
TEST(CrossClass, CylinderCandidateIsAbsorbedAtPromotion) {
  LandmarkRegistry map;
  std::mt19937 rng(6);
  MapUpdate u;
  for (int frame = 1; frame <= 5; ++frame)
    u = map.integrate(frame, 0.1 * frame,
                      {test::measure(shade(), kCamera, rng),
                       test::measure(bandAsCylinder(0.2, 0.3), kCamera, rng)},
                      kCamera, Matrix6d::Zero());
  ASSERT_EQ(map.landmarks().size(), 1u);
  EXPECT_EQ(map.landmarks().begin()->second.quadric_map.quadricClass(), QuadricClass::kCone);
  EXPECT_EQ(map.landmarks().begin()->second.observations, 10);
  EXPECT_EQ(u.promoted.size(), 1u);
  EXPECT_EQ(u.measurements[1].fate, MeasurementFate::kLandmark);
  EXPECT_TRUE(u.measurements[1].without_factor);
  EXPECT_TRUE(map.candidates().empty());
}

// The reverse: a cylinder landmark and a band of it fitted as a cone of small half-angle.
TEST(CrossClass, ConeObservationsOfACylinderCountOnTheCylinder) {
  const Eigen::Vector3d centre(0.2, -0.3, 0.6);
  const test::TrueLandmark bin = test::cylinder(centre, Eigen::Vector3d::UnitZ(), 0.12, 0.2);
  // Half-angle 0.05 rad with radius 0.12 m at the band's middle: apex 2.4 m below it.
  const double beta = 0.05, s_mid = 0.12 / std::tan(beta);
  const double s0 = s_mid - 0.1, s1 = s_mid + 0.1, r1 = s1 * std::tan(beta);
  const test::TrueLandmark as_cone{
      quadricFromShape(
          ConeShape{centre - s_mid * Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(), beta}),
      {Eigen::Vector3d(-r1, -r1, s0), Eigen::Vector3d(r1, r1, s1)}};
  LandmarkRegistry map;
  std::mt19937 rng(7);
  for (int frame = 1; frame <= 15; ++frame) {
    std::vector<QuadricMeasurement> seen{test::measure(bin, kCamera, rng)};
    if (frame > 5)
      seen.push_back(test::measure(as_cone, kCamera, rng, 0.5));
    map.integrate(frame, 0.1 * frame, seen, kCamera, Matrix6d::Zero());
  }
  ASSERT_EQ(map.landmarks().size(), 1u);
  EXPECT_EQ(map.landmarks().begin()->second.quadric_map.quadricClass(), QuadricClass::kCylinder);
  EXPECT_EQ(map.landmarks().begin()->second.observations, 25);
  EXPECT_TRUE(map.candidates().empty());
}

// Must stay two: a thin post on the cone's axis (inside the shade's extent) and a sleeve 4 cm
// outside the shade are other surfaces and become cylinder landmarks of their own.
TEST(CrossClass, NearbyCylindersStayLandmarksOfTheirOwn) {
  const test::TrueLandmark post = test::cylinder(kApex + 0.3 * kAxis, kAxis, 0.015, 0.2);
  const test::TrueLandmark sleeve = bandAsCylinder(0.2, 0.3, 0.04);
  LandmarkRegistry map;
  std::mt19937 rng(8);
  for (int frame = 1; frame <= 12; ++frame)
    map.integrate(frame, 0.1 * frame,
                  {test::measure(shade(), kCamera, rng), test::measure(post, kCamera, rng),
                   test::measure(sleeve, kCamera, rng)},
                  kCamera, Matrix6d::Zero());
  ASSERT_EQ(map.landmarks().size(), 3u);
  int cylinders = 0;
  for (const auto& [id, landmark] : map.landmarks()) {
    cylinders += landmark.quadric_map.quadricClass() == QuadricClass::kCylinder;
    EXPECT_EQ(landmark.observations, 12) << "landmark " << id;
  }
  EXPECT_EQ(cylinders, 2);
}

// A point of the shade at depth s below the apex (on the side facing the camera, -x) and the
// outward unit normal of the cone there.
void shadePoint(double s, Eigen::Vector3d* point, Eigen::Vector3d* normal) {
  const Eigen::Vector3d radial = -Eigen::Vector3d::UnitX();
  *point = kApex + s * kAxis + s * std::tan(kHalfAngle) * radial;
  *normal = std::cos(kHalfAngle) * radial - std::sin(kHalfAngle) * kAxis;
}

TEST(CrossClass, SampsonDistanceOfAnEllipsoid) {
  const QuadricModel ellipsoid(QuadricClass::kGeneral, Eigen::Isometry3d::Identity(),
                               Eigen::Vector3d(1 / 0.13, 1 / 0.08, 1 / 0.07),
                               Eigen::Vector4d(1, 1, 1, -1));
  EXPECT_NEAR(surfaceDistance(ellipsoid, Eigen::Vector3d(0.13, 0, 0)), 0.0, 1e-12);
  EXPECT_NEAR(surfaceDistance(ellipsoid, Eigen::Vector3d(0, 0, 0.08)), 0.01, 1e-3);
  EXPECT_NEAR(surfaceDistance(ellipsoid, Eigen::Vector3d(0, 0.07, 0)), 0.01, 1e-3);
}

// test::measure re-expresses a measurement by a random symmetry, for a sphere any rotation, which
// turns its box of supporting points into a much larger axis-aligned box; a segmenter reports a
// sphere in a camera-aligned frame. This keeps measure's noise and puts the frame back.
QuadricMeasurement cameraAlignedSphere(const test::TrueLandmark& sphere, std::mt19937& rng) {
  QuadricMeasurement m = test::measure(sphere, kCamera, rng);
  Eigen::Isometry3d T_camera_sphere = Eigen::Isometry3d::Identity();
  T_camera_sphere.translation() = m.quadric_camera.pose().translation();
  m.quadric_camera = QuadricModel(QuadricClass::kSphere, T_camera_sphere, m.quadric_camera.scale(),
                                  m.quadric_camera.signature());
  const ExtentBox box = sphere.extent.transformed(T_camera_sphere.inverse() * kCamera.inverse() *
                                                  sphere.quadric_world.pose());
  m.extent_min = box.min;
  m.extent_max = box.max;
  m.covariance = test::measurementCovariance(m.quadric_camera);
  return m;
}

// A patch of the shade fitted as a sphere (tangent to it along the circle through the patch:
// centre on the axis, radius = the circle's radius / cos(half-angle)) counts on the cone; a ball
// touching the shade from outside is another surface and becomes a sphere landmark.
TEST(CrossClass, SpherePatchOfAConeCountsOnTheConeABallBesideItDoesNot) {
  Eigen::Vector3d p, n;
  shadePoint(0.25, &p, &n);
  const double R = 0.25 * std::tan(kHalfAngle) / std::cos(kHalfAngle);
  test::TrueLandmark patch = test::sphere(p - R * n, R);
  patch.extent = {(R * n).array() - 0.04, (R * n).array() + 0.04};
  EXPECT_LT(crossClassDistance(patch.quadric_world, patch.extent, shade().quadric_world), 0.01);
  const test::TrueLandmark ball = test::sphere(p + 0.06 * n, 0.06);
  EXPECT_GT(crossClassDistance(ball.quadric_world, ball.extent, shade().quadric_world), 0.03);

  LandmarkRegistry map;
  std::mt19937 rng(10);
  for (int frame = 1; frame <= 15; ++frame) {
    std::vector<QuadricMeasurement> seen{test::measure(shade(), kCamera, rng),
                                         test::measure(ball, kCamera, rng)};
    if (frame > 5)
      seen.push_back(cameraAlignedSphere(patch, rng));
    const MapUpdate u = map.integrate(frame, 0.1 * frame, seen, kCamera, Matrix6d::Zero());
    if (frame > 5) {
      EXPECT_EQ(u.measurements[2].fate, MeasurementFate::kLandmark) << "frame " << frame;
      EXPECT_TRUE(u.measurements[2].without_factor);
      EXPECT_EQ(map.landmark(u.measurements[2].id).quadric_map.quadricClass(), QuadricClass::kCone);
    }
  }
  ASSERT_EQ(map.landmarks().size(), 2u);  // the cone and the ball
  for (const auto& [id, landmark] : map.landmarks())
    EXPECT_EQ(landmark.observations,
              landmark.quadric_map.quadricClass() == QuadricClass::kCone ? 25 : 15);
}

test::TrueLandmark ellipsoid(const Eigen::Vector3d& centre, const Eigen::Vector3d& semi_axes,
                             const ExtentBox& box) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = centre;
  return {QuadricModel(QuadricClass::kGeneral, pose, semi_axes.cwiseInverse(),
                       Eigen::Vector4d(1, 1, 1, -1)),
          box};
}

// A cushion-like ellipsoid seen from above. A general fit of its top that came out larger (radii
// +25-50 %, centre lower, the top in place) fails the association gate of the parameters but lies
// on the landmark over the observed top: it counts on it. An ellipsoid 9 cm beside it (25 cm
// between centres, outside the association gate) does not.
TEST(CrossClass, BiasedEllipsoidFitOfAPatchCountsOnItsLandmark) {
  const Eigen::Vector3d c(0.2, 0.6, 0.3);
  const test::TrueLandmark cushion =
      ellipsoid(c, Eigen::Vector3d(0.13, 0.08, 0.07),
                {Eigen::Vector3d(-0.13, -0.08, 0.0), Eigen::Vector3d(0.13, 0.08, 0.07)});
  const test::TrueLandmark biased_top =
      ellipsoid(c - Eigen::Vector3d(0, 0, 0.015), Eigen::Vector3d(0.16, 0.12, 0.085),
                {Eigen::Vector3d(-0.08, -0.06, 0.06), Eigen::Vector3d(0.08, 0.06, 0.085)});
  const test::TrueLandmark beside =
      ellipsoid(c + Eigen::Vector3d(0, 0.25, 0), Eigen::Vector3d(0.13, 0.08, 0.07),
                {Eigen::Vector3d(-0.13, -0.08, 0.0), Eigen::Vector3d(0.13, 0.08, 0.07)});
  EXPECT_LT(crossClassDistance(biased_top.quadric_world, biased_top.extent, cushion.quadric_world),
            0.01);
  EXPECT_GT(crossClassDistance(beside.quadric_world, beside.extent, cushion.quadric_world), 0.03);

  LandmarkRegistry map;
  std::mt19937 rng(11);
  for (int frame = 1; frame <= 15; ++frame) {
    std::vector<QuadricMeasurement> seen{test::measure(cushion, kCamera, rng)};
    if (frame > 5) {
      seen.push_back(test::measure(biased_top, kCamera, rng));
      seen.push_back(test::measure(beside, kCamera, rng));
    }
    const MapUpdate u = map.integrate(frame, 0.1 * frame, seen, kCamera, Matrix6d::Zero());
    if (frame > 5) {
      EXPECT_EQ(u.measurements[1].fate, MeasurementFate::kLandmark) << "frame " << frame;
      EXPECT_TRUE(u.measurements[1].without_factor);
      EXPECT_NE(u.measurements[1].landmark_association.outcome, AssociationOutcome::kMatched);
      EXPECT_FALSE(u.measurements[2].without_factor);
    }
  }
  ASSERT_EQ(map.landmarks().size(),
            2u);  // the cushion (counting the biased fits) and its neighbour
  EXPECT_EQ(map.landmarks().begin()->second.observations, 25);
}

// Through the mapper: the absorbed cylinder measurements make no factors (a cylinder measurement of
// a cone landmark has no observation cost), every frame is processed, the map is the cone alone.
TEST(CrossClass, MapperKeepsOneConeLandmark) {
  QuadricMapper mapper;
  std::mt19937 rng(9);
  for (int frame = 0; frame < 30; ++frame) {
    FrameMeasurements measurements;
    measurements.stamp = 1.0 + frame / 30.0;
    measurements.observations = {test::measure(shade(), kCamera, rng),
                                 test::measure(bandAsCylinder(0.2, 0.3), kCamera, rng)};
    OdometryInput odometry;
    odometry.T_odom_camera = kCamera;
    const MapperFrameResult r = mapper.process(measurements, odometry);
    ASSERT_EQ(r.status, FrameStatus::kOk) << r.message;
  }
  const std::vector<QuadricLandmark> landmarks = mapper.landmarks();
  ASSERT_EQ(landmarks.size(), 1u);
  EXPECT_EQ(landmarks[0].quadric_map.quadricClass(), QuadricClass::kCone);
  EXPECT_EQ(landmarks[0].observations, 60);
  const ConeShape estimate = coneShape(landmarks[0].quadric_map);
  EXPECT_LT((estimate.apex - kApex).norm(), 0.02);
  EXPECT_NEAR(estimate.half_angle, kHalfAngle, 0.02);
}

// The gate follows the measurement's own scatter: a far view's fit (points 1.5 cm about it) that
// lies 4 cm off the cone over its box is counted on the cone, as a frame that noisy cannot tell
// the two surfaces apart; the same surface measured tightly (3 mm) is another surface, a landmark
// of its own.
TEST(CrossClass, TheGateFollowsTheMeasurementsScatter) {
  const test::TrueLandmark sleeve = bandAsCylinder(0.2, 0.3, 0.04);
  ASSERT_GT(crossClassDistance(sleeve.quadric_world, sleeve.extent, shade().quadric_world), 0.035);
  QuadricAssociator::Params gate;
  EXPECT_DOUBLE_EQ(gate.crossClassGate(0.003), gate.cross_class_distance);
  EXPECT_DOUBLE_EQ(gate.crossClassGate(0.015), 3.0 * 0.015);
  gate.cross_class_distance = 0.0;  // the test off stays off
  EXPECT_DOUBLE_EQ(gate.crossClassGate(0.015), 0.0);
  for (const double fit_rms : {0.015, 0.003}) {
    LandmarkRegistry map;
    std::mt19937 rng(9);
    for (int frame = 1; frame <= 12; ++frame) {
      QuadricMeasurement far_fit = test::measure(sleeve, kCamera, rng);
      far_fit.fit_rms = fit_rms;
      map.integrate(frame, 0.1 * frame, {test::measure(shade(), kCamera, rng), far_fit}, kCamera,
                    Matrix6d::Zero());
    }
    EXPECT_EQ(map.landmarks().size(), fit_rms > 0.01 ? 1u : 2u) << "fit RMS " << fit_rms;
  }
}

// Within a class: a partial view of the cone (a band 5 cm high) fitted with its apex 15 cm higher
// and a smaller half-angle, so that the band lies on the cone while the parameters are far outside
// the association gate, counts on the cone landmark without a factor instead of starting a second
// cone landmark.
TEST(CrossClass, APartialViewWhoseParametersFailTheGateCountsOnItsLandmark) {
  const double s0 = 0.25, s1 = 0.3, s_mid = 0.5 * (s0 + s1), shift = 0.15;
  // The band's cone: apex `shift` up the axis, radius at the band's middle the shade's.
  const double beta = std::atan(s_mid * std::tan(kHalfAngle) / (s_mid + shift));
  const double r1 = (s1 + shift) * std::tan(beta);
  const test::TrueLandmark band{
      quadricFromShape(ConeShape{kApex - shift * kAxis, kAxis, beta}),
      {Eigen::Vector3d(-r1, -r1, s0 + shift), Eigen::Vector3d(r1, r1, s1 + shift)}};
  ASSERT_LT(crossClassDistance(band.quadric_world, band.extent, shade().quadric_world), 0.01);
  LandmarkRegistry map;
  std::mt19937 rng(10);
  const int cone_id = mapTheCone(map, rng);
  ASSERT_EQ(map.landmarks().size(), 1u);
  for (int frame = 6; frame <= 20; ++frame) {
    // A fit of a few thousand pixels: its covariance (pixel noise) as tight as its scatter.
    QuadricMeasurement partial = test::measure(band, kCamera, rng, 0.01);
    partial.covariance *= 1e-4;
    const MapUpdate u = map.integrate(frame, 0.1 * frame, {partial}, kCamera, Matrix6d::Zero());
    ASSERT_EQ(u.measurements.size(), 1u);
    EXPECT_NE(u.measurements[0].landmark_association.outcome, AssociationOutcome::kMatched)
        << "frame " << frame << ": the band's parameters should fail the gate";
    EXPECT_EQ(u.measurements[0].fate, MeasurementFate::kLandmark) << "frame " << frame;
    EXPECT_EQ(u.measurements[0].id, cone_id);
    EXPECT_TRUE(u.measurements[0].without_factor);
  }
  EXPECT_EQ(map.landmarks().size(), 1u);
  EXPECT_TRUE(map.candidates().empty());
}

}  // namespace
}  // namespace quadric_slam
