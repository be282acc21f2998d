#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "quadric_slam/geometry/quadric_class.h"
#include "quadric_slam/sim/random.h"
#include "quadric_slam/sim/surfaces.h"
#include "quadric_slam/sim/trajectory.h"

using namespace quadric_slam;

namespace {

// The map schema's quadric evaluated at a world point (eq. 5 with T = T_WQ^-1):
// (S p_Q)^T D(sigma_1..3) (S p_Q) + sigma_4, p_Q = T_WQ^-1 p_W.
double quadricValue(const MapFileQuadric& q, const Eigen::Vector3d& p_world) {
  Eigen::Vector4d sigma;
  if (q.quadric_class == "plane")
    sigma = defaultSignature(QuadricClass::kPlane);
  else if (q.quadric_class == "sphere" || q.quadric_class == "ellipsoid")
    sigma = defaultSignature(QuadricClass::kSphere);
  else if (q.quadric_class == "cylinder")
    sigma = defaultSignature(QuadricClass::kCylinder);
  else
    sigma = defaultSignature(QuadricClass::kCone);
  const Eigen::Vector3d s = q.scale.cwiseProduct(q.T_map_quadric.inverse() * p_world);
  return sigma[0] * s[0] * s[0] + sigma[1] * s[1] * s[1] + sigma[2] * s[2] * s[2] + sigma[3];
}

Scene oneOfEach() {
  Scene scene;
  auto add = [&](const std::string& name, PrimitiveType type, const Eigen::Vector3d& position,
                 const Eigen::Vector3d& axis) {
    PrimitiveSpec p;
    p.name = name;
    p.type = type;
    p.T_world_primitive = lookAt(position, position + axis);
    p.T_world_primitive.translation() = position;
    scene.primitives.push_back(p);
    return &scene.primitives.back();
  };
  add("rect", PrimitiveType::kRectangle, {0.3, 0.2, 1.0}, {1, 2, 3})->size = {0, 0.5, 0.4};
  add("box", PrimitiveType::kBox, {-0.5, 0.1, 2.0}, {0, 1, 1})->size = {0.3, 0.4, 0.5};
  add("ball", PrimitiveType::kSphere, {0.2, -0.3, 1.5}, {0, 0, 1})->radius = 0.25;
  PrimitiveSpec* cyl = add("can", PrimitiveType::kCylinder, {0.0, 0.4, 1.7}, {1, 0.5, 0.2});
  cyl->radius = 0.1;
  cyl->length = 0.5;
  cyl->capped = true;
  PrimitiveSpec* cone = add("shade", PrimitiveType::kCone, {-0.2, -0.1, 0.8}, {0.3, 0.2, 1});
  cone->half_angle = 0.4;
  cone->z_min = 0.2;
  cone->z_max = 0.6;
  add("egg", PrimitiveType::kEllipsoid, {0.4, 0.4, 2.2}, {1, 1, 0})->radii = {0.3, 0.2, 0.1};
  return scene;
}

}  // namespace

TEST(Surfaces, ExpandPrimitivesWithIdsInSceneOrder) {
  const std::vector<Surface> s = buildSurfaces(oneOfEach());
  // rect 1, box 2..7, ball 8, can 9 (+ caps 10, 11), shade 12, egg 13.
  ASSERT_EQ(s.size(), 13u);
  for (std::size_t i = 0; i < s.size(); ++i)
    EXPECT_EQ(s[i].id(), static_cast<int>(i + 1));
  EXPECT_EQ(s[1].name(), "box/+x");
  EXPECT_EQ(s[10].name(), "can/-z");
  EXPECT_EQ(s[11].toMapQuadric().quadric_class, "cone");
  EXPECT_EQ(s[12].toMapQuadric().quadric_class, "ellipsoid");
}

// Points found by ray casting every surface lie on the quadric written to quadrics_gt.yaml, within
// its extent, and the human-readable shape agrees with pose and scale.
TEST(Surfaces, HitPointsLieOnTheMapQuadric) {
  const std::vector<Surface> surfaces = buildSurfaces(oneOfEach());
  SimRandom random(17);
  for (const Surface& surface : surfaces) {
    const MapFileQuadric q = surface.toMapQuadric();
    int hits = 0;
    for (int i = 0; i < 4000 && hits < 50; ++i) {
      // Rays from a random point 3 m away towards a random point near the surface.
      const Eigen::Vector3d dir(random.normal(), random.normal(), random.normal());
      const Eigen::Vector3d origin = surface.boundCentre() + 3.0 * dir.normalized();
      const Eigen::Vector3d target =
          surface.boundCentre() +
          surface.boundRadius() *
              Eigen::Vector3d(random.normal(), random.normal(), random.normal()) / 2;
      double t;
      Eigen::Vector3d normal, local;
      if (!surface.intersect(origin, target - origin, 1e-6, 1e9, &t, &normal, &local))
        continue;
      ++hits;
      const Eigen::Vector3d p = origin + t * (target - origin);
      EXPECT_NEAR(quadricValue(q, p), 0.0, 1e-9) << surface.name();
      // ... inside the piece's extent (quadric frame), which the evaluator compares boxes with.
      ASSERT_TRUE(q.has_extent) << surface.name();
      const Eigen::Vector3d p_quadric = q.T_map_quadric.inverse() * p;
      EXPECT_TRUE((p_quadric.array() >= q.extent_min.array() - 1e-9).all() &&
                  (p_quadric.array() <= q.extent_max.array() + 1e-9).all())
          << surface.name() << " " << p_quadric.transpose();
      EXPECT_NEAR(normal.norm(), 1.0, 1e-9);
      // The normal is the quadric's gradient direction at p (a plane's x^2 has a double root:
      // its normal is the quadric x axis instead).
      if (q.quadric_class == "plane") {
        EXPECT_NEAR(std::abs(normal.dot(q.T_map_quadric.linear().col(0))), 1.0, 1e-12);
        continue;
      }
      const double h = 1e-6;
      Eigen::Vector3d gradient;
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d e = Eigen::Vector3d::Zero();
        e[k] = h;
        gradient[k] = (quadricValue(q, p + e) - quadricValue(q, p - e)) / (2 * h);
      }
      EXPECT_NEAR(std::abs(gradient.normalized().dot(normal)), 1.0, 1e-5) << surface.name();
    }
    EXPECT_GE(hits, 50) << surface.name();
    const Eigen::Vector3d t = q.T_map_quadric.translation();
    const Eigen::Matrix3d R = q.T_map_quadric.linear();
    if (q.quadric_class == "plane") {
      EXPECT_NEAR((Eigen::Vector3d(q.shape.at("normal").data()) - R.col(0)).norm(), 0, 1e-12);
      EXPECT_NEAR(q.shape.at("offset")[0], R.col(0).dot(t), 1e-12);
      EXPECT_EQ(q.scale, Eigen::Vector3d::Ones());
    } else if (q.quadric_class == "sphere") {
      EXPECT_NEAR(q.shape.at("radius")[0], 0.25, 1e-12);
      EXPECT_NEAR(q.scale.x(), 4.0, 1e-12);
    } else if (q.quadric_class == "cylinder") {
      EXPECT_NEAR(q.shape.at("radius")[0], 0.1, 1e-12);
      EXPECT_NEAR(
          (Eigen::Vector3d(q.shape.at("axis").data()) - Eigen::Vector3d(1, 0.5, 0.2).normalized())
              .norm(),
          0, 1e-9);
      EXPECT_EQ(q.scale.z(), 1.0);
    } else if (q.quadric_class == "cone") {
      EXPECT_NEAR(q.shape.at("half_angle")[0], 0.4, 1e-12);
      EXPECT_NEAR(q.scale.x(), 1.0 / std::tan(0.4), 1e-12);
      EXPECT_NEAR(
          (Eigen::Vector3d(q.shape.at("apex").data()) - Eigen::Vector3d(-0.2, -0.1, 0.8)).norm(), 0,
          1e-12);
    }
  }
}

TEST(Surfaces, TruncatedConeAndFiniteCylinderAreBounded) {
  const std::vector<Surface> surfaces = buildSurfaces(oneOfEach());
  const Surface& cone = surfaces[11];
  const Surface& can = surfaces[8];
  SimRandom random(3);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d origin =
        Eigen::Vector3d(random.normal(), random.normal(), random.normal()) * 2;
    const Eigen::Vector3d direction(random.normal(), random.normal(), random.normal());
    double t;
    Eigen::Vector3d normal, local;
    if (cone.intersect(origin, direction, 0, 1e9, &t, &normal, &local)) {
      EXPECT_GE(local.z(), 0.2 - 1e-9);
      EXPECT_LE(local.z(), 0.6 + 1e-9);
    }
    if (can.intersect(origin, direction, 0, 1e9, &t, &normal, &local)) {
      EXPECT_LE(std::abs(local.z()), 0.25 + 1e-9);
    }
  }
}

TEST(Surfaces, BadDimensionsNameThePrimitive) {
  Scene scene;
  PrimitiveSpec p;
  p.name = "lamp";
  p.type = PrimitiveType::kCone;
  p.half_angle = 2.0;
  scene.primitives.push_back(p);
  try {
    buildSurfaces(scene);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("lamp"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("half_angle"), std::string::npos);
  }
}

TEST(Surfaces, OnlyClosedSolidFacesAreCulledFromBehind) {
  const std::vector<Surface> s = buildSurfaces(oneOfEach());
  EXPECT_FALSE(s[0].closedFace());  // a lone rectangle is two-sided
  EXPECT_TRUE(s[0].mayBeVisibleFrom(s[0].pose() * Eigen::Vector3d(-1, 0, 0)));
  for (int i = 1; i <= 6; ++i) {  // box faces: visible from outside only
    EXPECT_TRUE(s[i].closedFace());
    EXPECT_TRUE(s[i].mayBeVisibleFrom(s[i].pose() * Eigen::Vector3d(0.5, 0, 0))) << s[i].name();
    EXPECT_FALSE(s[i].mayBeVisibleFrom(s[i].pose() * Eigen::Vector3d(-0.01, 0, 0))) << s[i].name();
    // The outward normal points away from the box centre.
    const Eigen::Vector3d centre(-0.5, 0.1, 2.0);
    EXPECT_GT(s[i].pose().linear().col(0).dot(s[i].pose().translation() - centre), 0)
        << s[i].name();
  }
  EXPECT_FALSE(s[8].closedFace());  // the cylinder's lateral surface
  EXPECT_TRUE(s[9].closedFace());   // its caps
  EXPECT_TRUE(s[10].closedFace());
}

// Two walls of one noise-textured material carry different patterns (each surface reads its own
// part of the noise lattice): a real room's walls do not repeat each other pixel for pixel, and
// image corners matched from one such wall to the other would agree on a false motion.
TEST(Surfaces, SurfacesOfOneNoiseMaterialCarryDifferentPatterns) {
  Scene scene;
  for (const double x : {2.0, -2.0}) {
    PrimitiveSpec wall;
    wall.name = "wall";
    wall.type = PrimitiveType::kRectangle;
    wall.T_world_primitive.translation() = Eigen::Vector3d(x, 0, 0);
    wall.size = Eigen::Vector3d(0, 3, 2);
    wall.material.texture = Texture::kNoise;
    wall.material.texture_scale = 0.05;
    scene.primitives.push_back(wall);
  }
  const std::vector<Surface> walls = buildSurfaces(scene);
  ASSERT_EQ(walls.size(), 2u);
  int different = 0, samples = 0;
  double variation = 0;
  for (double y = -1.4; y < 1.4; y += 0.07)
    for (double z = -0.9; z < 0.9; z += 0.07) {
      const Eigen::Vector3d point(0, y, z);
      const Eigen::Vector3d a = walls[0].albedo(point), b = walls[1].albedo(point);
      different += (a - b).norm() > 0.05;
      variation += (a - walls[0].albedo(Eigen::Vector3d(0, y + 0.035, z))).norm();
      ++samples;
    }
  EXPECT_GT(variation / samples, 0.02) << "the texture does not vary over the wall";
  EXPECT_GT(different, samples / 2) << different << " of " << samples << " points differ";
  // The same surface gives the same pattern every time it is built (sequences are reproducible).
  EXPECT_EQ(buildSurfaces(scene)[1].albedo(Eigen::Vector3d(0, 0.3, 0.2)),
            walls[1].albedo(Eigen::Vector3d(0, 0.3, 0.2)));
}
