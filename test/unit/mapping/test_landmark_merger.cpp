// LandmarkMerger: the chi-square statistic is calibrated (mean k for two estimates of one surface,
// whatever frames they are expressed in), distinct surfaces are told apart by the parameters
// (parallel planes 3 cm apart) or by the extents (two table tops at one height 2 m apart), three
// fragments of a wall are found as duplicates, and the fusion's covariance is no larger than
// either part's.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <random>

#include "quadric_slam/geometry/symmetry.h"
#include "quadric_slam/mapping/landmark_merger.h"
#include "quadric_slam/mapping/surface_fusion.h"
#include "synthetic_world.h"

namespace quadric_slam {
namespace {

const Eigen::Vector3d kX = Eigen::Vector3d::UnitX(), kY = Eigen::Vector3d::UnitY(),
                      kZ = Eigen::Vector3d::UnitZ();

// A landmark of a true surface patch: estimate = truth, covariance sigma^2 I (1 mm / 1 mrad-like).
QuadricLandmark landmarkOf(int id, const test::TrueLandmark& truth, double sigma = 0.001,
                           int observations = 10) {
  QuadricLandmark l;
  l.id = id;
  l.quadric_map = truth.quadric_world;
  const int k = minimalDimension(truth.quadric_world.quadricClass());
  l.covariance = sigma * sigma * Eigen::MatrixXd::Identity(k, k);
  l.extent_min = truth.extent.min;
  l.extent_max = truth.extent.max;
  l.observations = observations;
  return l;
}

// A fragment of the wall x = 3 (normal -x), spanning world y in [y0, y1] and z in [0, 2.5], in a
// frame of its own (centred on the fragment).
test::TrueLandmark wallFragment(double y0, double y1) {
  return test::plane(Eigen::Vector3d(3.0, 0.5 * (y0 + y1), 1.25), -kX, kY, 0.5 * (y1 - y0), 1.25);
}

double minEigenvalue(const Eigen::MatrixXd& m) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (m + m.transpose()))
      .eigenvalues()
      .minCoeff();
}

// A merger without the model-error floor: the statistic of the measured covariances alone.
LandmarkMerger mergerWithoutFloor() {
  LandmarkMerger::Params p;
  p.floor_translation_sigma = p.floor_rotation_sigma = p.floor_scale_fraction = 0.0;
  return LandmarkMerger(p);
}

// A sample of N(0, C).
Eigen::VectorXd gaussianSample(const Eigen::MatrixXd& C, std::mt19937& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::VectorXd n(C.rows());
  for (int i = 0; i < n.size(); ++i)
    n[i] = gauss(rng);
  return Eigen::MatrixXd(C.llt().matrixL()) * n;
}

TEST(LandmarkMerger, ParamsValidate) {
  LandmarkMerger::Params p;
  EXPECT_NO_THROW(p.validate());
  p.gate_probability = 1.0;
  EXPECT_THROW(LandmarkMerger{p}, std::invalid_argument);
  p = {};
  p.floor_translation_sigma = -0.1;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.missing_rotation_sigma = 0.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.extent_margin = -0.01;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

// Two independent estimates of one surface, the second in a random frame of its symmetry orbit:
// without a floor, d^2 follows chi2_k (mean k, 99.9% under the gate). A statistic in the wrong
// tangent (a missing re-expression of the covariance, a wrong sign of the offset) fails this.
TEST(LandmarkMerger, SquaredDistanceIsChiSquareForOneSurface) {
  const LandmarkMerger merger = mergerWithoutFloor();
  std::mt19937 rng(7);
  for (QuadricClass c : kAllQuadricClasses) {
    const int k = minimalDimension(c);
    const int trials = 2000;
    double sum = 0.0;
    int inside = 0;
    for (int t = 0; t < trials; ++t) {
      const QuadricModel truth = test::randomQuadric(c, rng);
      // Correlated covariances, a few mm / mrad.
      auto randomCovariance = [&]() {
        Eigen::MatrixXd A = Eigen::MatrixXd::Random(k, k) * 0.002;
        return Eigen::MatrixXd(A * A.transpose() + 1e-6 * Eigen::MatrixXd::Identity(k, k));
      };
      const Eigen::MatrixXd Ca = randomCovariance(), Cb = randomCovariance();
      auto sample = [&](const Eigen::MatrixXd& C) {
        return truth.plusMinimal(gaussianSample(C, rng));
      };
      QuadricLandmark a, b;
      a.id = 1;
      a.quadric_map = sample(Ca);
      a.covariance = Ca;
      const QuadricModel b0 = sample(Cb);
      const Eigen::Isometry3d G = test::randomSymmetry(c, rng);
      b.id = 2;
      b.quadric_map = QuadricModel(c, b0.pose() * G, b0.scale(), b0.signature());
      const Eigen::MatrixXd M = minimalAdjoint(c, G.inverse());
      b.covariance = M * Cb * M.transpose();
      const double d2 = merger.compare(a, b).squared_distance;
      sum += d2;
      inside += d2 <= merger.gate(c);
    }
    const double mean = sum / trials;
    EXPECT_NEAR(mean, k, 0.1 * k) << toString(c);
    EXPECT_GE(inside, 0.99 * trials) << toString(c);
  }
}

TEST(LandmarkMerger, ThreeWallFragmentsAreOneSurface) {
  const LandmarkMerger merger;
  // Fragments with gaps of 4 and 6 cm (the segmenter lost the points along a door frame).
  std::map<int, QuadricLandmark> map;
  map[1] = landmarkOf(1, wallFragment(-2.0, -0.72));
  map[2] = landmarkOf(2, wallFragment(-0.68, 0.6), 0.001, 30);
  map[3] = landmarkOf(3, wallFragment(0.66, 2.0));
  // Estimates off by a little, as from different frames: 1.5 mm and 0.1 deg.
  map[1].quadric_map = map[1].quadric_map.plusMinimal(Eigen::Vector3d(0.0015, 0.0, 0.0));
  map[3].quadric_map = map[3].quadric_map.plusMinimal(Eigen::Vector3d(0.0, 0.0017, 0.0));
  const std::vector<DuplicatePair> pairs = merger.findDuplicates(map);
  ASSERT_EQ(pairs.size(), 2u);  // 1-2 and 2-3 touch; 1 and 3 are 1.3 m apart
  std::set<std::pair<int, int>> found;
  for (const DuplicatePair& pair : pairs)
    found.insert({std::min(pair.id_a, pair.id_b), std::max(pair.id_a, pair.id_b)});
  EXPECT_EQ(found, (std::set<std::pair<int, int>>{{1, 2}, {2, 3}}));
  EXPECT_LE(pairs[0].squared_distance, pairs[1].squared_distance);
  // Restricted to landmark 3, only its pair.
  const std::set<int> subset{3};
  const std::vector<DuplicatePair> of_three = merger.findDuplicates(map, &subset);
  ASSERT_EQ(of_three.size(), 1u);
  EXPECT_EQ(std::min(of_three[0].id_a, of_three[0].id_b), 2);

  // Merging 1 into 2 and then 3 into the result: one landmark spanning the whole wall.
  EXPECT_TRUE(LandmarkMerger::survives(map[2], map[1]));
  const QuadricLandmark two = merger.fused(map[2], map[1]);
  EXPECT_TRUE(merger.compare(two, map[3]).sameSurface());
  const QuadricLandmark all = merger.fused(two, map[3]);
  EXPECT_EQ(all.id, 2);
  EXPECT_EQ(all.observations, 50);
  // The extent covers both ends of the wall (world y = -2 and y = 2).
  const ExtentBox box_world =
      ExtentBox{all.extent_min, all.extent_max}.transformed(all.quadric_map.pose());
  EXPECT_LT(box_world.min.y(), -1.99);
  EXPECT_GT(box_world.max.y(), 1.99);
  EXPECT_GT(std::abs(planeShape(all.quadric_map).normal.dot(kX)), 1.0 - 1e-5);
}

// Same infinite plane, far-apart patches: the parameters agree, the extents decide.
TEST(LandmarkMerger, TwoTablesAtOneHeightStayTwo) {
  const LandmarkMerger merger;
  const QuadricLandmark left =
      landmarkOf(1, test::plane(Eigen::Vector3d(0, 0, 0.75), kZ, kX, 0.5, 0.4));
  const QuadricLandmark right =
      landmarkOf(2, test::plane(Eigen::Vector3d(2.0, 0, 0.75), kZ, kX, 0.5, 0.4));
  const LandmarkMerger::Comparison c = merger.compare(left, right);
  EXPECT_TRUE(c.within_gate);
  EXPECT_FALSE(c.extents_touch);
  EXPECT_FALSE(c.sameSurface());
  EXPECT_TRUE(merger.findDuplicates({{1, left}, {2, right}}).empty());
  // Pushed together (a 4 cm gap, within twice the margin) they are one surface.
  const QuadricLandmark near =
      landmarkOf(2, test::plane(Eigen::Vector3d(1.04, 0, 0.75), kZ, kX, 0.5, 0.4));
  EXPECT_TRUE(merger.compare(left, near).sameSurface());
  // Unknown extents are no evidence of touching.
  QuadricLandmark unknown = near;
  unknown.extent_min.setZero();
  unknown.extent_max.setZero();
  EXPECT_FALSE(merger.compare(left, unknown).extents_touch);
}

// Parallel planes 3 cm apart with overlapping extents (a cabinet door in front of its frame): the
// parameters decide.
TEST(LandmarkMerger, ParallelPlanesThreeCentimetresApartStayTwo) {
  const LandmarkMerger merger;
  const QuadricLandmark back = landmarkOf(1, test::plane(Eigen::Vector3d(3, 0, 1), -kX, kY, 1, 1));
  const QuadricLandmark front =
      landmarkOf(2, test::plane(Eigen::Vector3d(2.97, 0.2, 1), -kX, kY, 0.4, 0.4));
  const LandmarkMerger::Comparison c = merger.compare(back, front);
  EXPECT_TRUE(c.extents_touch);
  EXPECT_FALSE(c.within_gate) << "d2 " << c.squared_distance;
  // A missing covariance is inflated (2 cm): then the 3 cm no longer tells them apart.
  QuadricLandmark unrefined = front;
  unrefined.covariance.resize(0, 0);
  EXPECT_TRUE(merger.compare(back, unrefined).within_gate);
}

// Two estimates of one surface that share an error (both seen from the same drifted views: a
// batch's marginals relative to its first frame): with their cross-covariance the statistic is
// chi2_k again, whatever frame the second is expressed in; from the marginals alone it is far
// smaller (the shared error counted twice).
TEST(LandmarkMerger, CorrelatedEstimatesAreComparedByTheCovarianceOfTheirDifference) {
  const LandmarkMerger merger = mergerWithoutFloor();
  std::mt19937 rng(11);
  for (QuadricClass c : kAllQuadricClasses) {
    const int k = minimalDimension(c);
    auto sampleOf = [&](const Eigen::MatrixXd& C) { return gaussianSample(C, rng); };
    const Eigen::MatrixXd shared = 0.03 * 0.03 * Eigen::MatrixXd::Identity(k, k);
    const Eigen::MatrixXd own = 0.002 * 0.002 * Eigen::MatrixXd::Identity(k, k);
    const int trials = 2000;
    double with_cross = 0.0, marginals_only = 0.0;
    for (int t = 0; t < trials; ++t) {
      const QuadricModel truth = test::randomQuadric(c, rng);
      const Eigen::VectorXd e = sampleOf(shared);
      QuadricLandmark a, b;
      a.id = 1;
      a.quadric_map = truth.plusMinimal(e + sampleOf(own));
      a.covariance = shared + own;
      const QuadricModel b0 = truth.plusMinimal(e + sampleOf(own));
      const Eigen::Isometry3d G = test::randomSymmetry(c, rng);
      b.id = 2;
      b.quadric_map = QuadricModel(c, b0.pose() * G, b0.scale(), b0.signature());
      const Eigen::MatrixXd M = minimalAdjoint(c, G.inverse());
      b.covariance = M * (shared + own) * M.transpose();
      const Eigen::MatrixXd cross = shared * M.transpose();  // Cov(a, b) in b's own tangent
      with_cross += merger.compare(a, b, &cross).squared_distance;
      marginals_only += merger.compare(a, b).squared_distance;
    }
    EXPECT_NEAR(with_cross / trials, k, 0.1 * k) << toString(c);
    EXPECT_LT(marginals_only / trials, 0.1 * k) << toString(c);
  }
}

// Parallel planes 3 cm apart whose marginals are 5 cm (both placed by the same uncertain views):
// the marginals alone cannot tell them apart, their cross-covariance can.
TEST(LandmarkMerger, SharedUncertaintyDoesNotMergeParallelPlanes) {
  const LandmarkMerger merger;
  QuadricLandmark back = landmarkOf(1, test::plane(Eigen::Vector3d(3, 0, 1), -kX, kY, 1, 1));
  QuadricLandmark front =
      landmarkOf(2, test::plane(Eigen::Vector3d(2.97, 0.2, 1), -kX, kY, 0.4, 0.4));
  // A shared offset error along the common normal (the frames have the same orientation, so it is
  // the same minimal vector in both).
  const Eigen::MatrixXd shared = diagonalMinimalCovariance(back.quadric_map, 0.05, 1e-6, 0.0);
  back.covariance += shared;
  front.covariance += shared;
  const Eigen::MatrixXd cross = shared;
  EXPECT_TRUE(merger.compare(back, front).sameSurface());
  const LandmarkMerger::Comparison c = merger.compare(back, front, &cross);
  EXPECT_TRUE(c.extents_touch);
  EXPECT_FALSE(c.within_gate) << "d2 " << c.squared_distance;
  LandmarkMerge merge;
  EXPECT_FALSE(merger.mergePair(back, false, front, false, &merge, &cross).has_value());
  EXPECT_TRUE(merger.mergePair(back, false, front, false, &merge).has_value());
  EXPECT_EQ(merge.survivor_id, 1);  // equal observations: the smaller id
  EXPECT_EQ(merge.merged_id, 2);
}

TEST(LandmarkMerger, OtherClassesAndKindsNeverMerge) {
  const LandmarkMerger merger;
  const QuadricLandmark plane = landmarkOf(1, test::plane(Eigen::Vector3d(0, 0, 0), kZ, kX, 1, 1));
  const QuadricLandmark sphere = landmarkOf(2, test::sphere(Eigen::Vector3d(0, 0, 0.2), 0.2));
  EXPECT_FALSE(merger.compare(plane, sphere).sameSurface());
  EXPECT_THROW(merger.fused(plane, sphere), std::invalid_argument);
  // A cylinder seen as two touching pieces along its axis is one; a thicker one is not.
  const QuadricLandmark lower =
      landmarkOf(3, test::cylinder(Eigen::Vector3d(1, 1, 0.3), kZ, 0.1, 0.3));
  const QuadricLandmark upper =
      landmarkOf(4, test::cylinder(Eigen::Vector3d(1, 1, 0.9), kZ, 0.1, 0.3));
  const QuadricLandmark thicker =
      landmarkOf(5, test::cylinder(Eigen::Vector3d(1, 1, 0.9), kZ, 0.13, 0.3));
  EXPECT_TRUE(merger.compare(lower, upper).sameSurface());
  EXPECT_FALSE(merger.compare(lower, thicker).sameSurface());
}

// Information adds: the fused covariance is below both parts (Loewner order), and with equal
// covariances the fused estimate is the midpoint.
TEST(LandmarkMerger, FusedCovarianceIsNoLargerThanEitherPart) {
  const LandmarkMerger merger;
  std::mt19937 rng(3);
  for (QuadricClass c : kAllQuadricClasses) {
    const int k = minimalDimension(c);
    const QuadricModel truth = test::randomQuadric(c, rng);
    QuadricLandmark a, b;
    a.id = 1;
    b.id = 2;
    a.observations = 8;
    b.observations = 3;
    Eigen::MatrixXd A = Eigen::MatrixXd::Random(k, k) * 0.003;
    Eigen::MatrixXd B = Eigen::MatrixXd::Random(k, k) * 0.002;
    a.covariance = A * A.transpose() + 1e-6 * Eigen::MatrixXd::Identity(k, k);
    b.covariance = B * B.transpose() + 4e-6 * Eigen::MatrixXd::Identity(k, k);
    a.quadric_map = truth;
    const Eigen::Isometry3d G = test::randomSymmetry(c, rng);
    const QuadricModel b0 = truth.plusMinimal(Eigen::VectorXd::Constant(k, 0.002));
    b.quadric_map = QuadricModel(c, b0.pose() * G, b0.scale(), b0.signature());
    const QuadricLandmark f = merger.fused(a, b);
    ASSERT_EQ(f.covariance.rows(), k);
    const Eigen::MatrixXd Cb_aligned =
        alignCovariance(b.quadric_map, b.covariance, a.quadric_map).matrix;
    EXPECT_GE(minEigenvalue(a.covariance - f.covariance), -1e-12) << toString(c);
    EXPECT_GE(minEigenvalue(Cb_aligned - f.covariance), -1e-12) << toString(c);
    EXPECT_LT(f.covariance.trace(), std::min(a.covariance.trace(), Cb_aligned.trace()));
    // The fused estimate is closer to each part, in that part's metric, than the other part is.
    const Eigen::VectorXd x_ab = surfaceOffset(a.quadric_map, b.quadric_map);
    const Eigen::VectorXd x_af = surfaceOffset(a.quadric_map, f.quadric_map);
    const Eigen::LLT<Eigen::MatrixXd> Ia(a.covariance);
    EXPECT_LT(x_af.dot(Ia.solve(x_af)), x_ab.dot(Ia.solve(x_ab))) << toString(c);
  }
  // Equal covariances: the midpoint.
  QuadricLandmark a = landmarkOf(1, test::plane(Eigen::Vector3d(0, 0, 1), kZ, kX, 1, 1));
  QuadricLandmark b = a;
  b.id = 2;
  b.quadric_map = a.quadric_map.plusMinimal(Eigen::Vector3d(0.004, 0.002, 0.0));
  const QuadricLandmark mid = merger.fused(a, b);
  EXPECT_NEAR(planeShape(mid.quadric_map).offset - planeShape(a.quadric_map).offset,
              0.5 * (planeShape(b.quadric_map).offset - planeShape(a.quadric_map).offset), 1e-5);
  EXPECT_NEAR(surfaceOffset(a.quadric_map, mid.quadric_map)[1], 0.001, 1e-5);
  // A missing covariance weighs in but yields no covariance; keep_estimate keeps the survivor's.
  b.covariance.resize(0, 0);
  EXPECT_EQ(merger.fused(a, b).covariance.size(), 0);
  const QuadricLandmark kept = merger.fused(a, b, true);
  EXPECT_TRUE(kept.quadric_map.pose().isApprox(a.quadric_map.pose()));
  EXPECT_TRUE(kept.covariance.isApprox(a.covariance));
}

TEST(LandmarkMerger, SurvivorHasMoreObservationsOrTheSmallerId) {
  QuadricLandmark a, b;
  a.id = 4;
  b.id = 9;
  a.observations = 3;
  b.observations = 5;
  EXPECT_TRUE(LandmarkMerger::survives(b, a));
  EXPECT_FALSE(LandmarkMerger::survives(a, b));
  b.observations = 3;
  EXPECT_TRUE(LandmarkMerger::survives(a, b));
  EXPECT_FALSE(LandmarkMerger::survives(b, a));
}

}  // namespace
}  // namespace quadric_slam
