// LandmarkRegistry: a surface becomes a landmark only after min_observations (5) frames, a
// detection seen 1-4 times never does and expires, ids are fresh, stable and never reused; a
// candidate of a landmark's surface joins it at promotion; merges are recorded for subscribers.
#include <gtest/gtest.h>

#include <random>

#include "quadric_slam/mapping/landmark_registry.h"
#include "synthetic_world.h"

namespace quadric_slam {
namespace {

const Eigen::Isometry3d kCamera =
    test::lookAlong(Eigen::Vector3d(-2.0, 0.0, 1.0), Eigen::Vector3d(1.0, 0.0, -0.4));

TEST(LandmarkRegistry, ParamsValidate) {
  LandmarkRegistry::Params p;
  EXPECT_NO_THROW(p.validate());
  p.min_observations = 0;
  EXPECT_THROW(LandmarkRegistry{p}, std::invalid_argument);
  p = {};
  p.candidate_timeout_frames = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.association.gate_probability = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

TEST(LandmarkRegistry, LandmarkOnlyAfterFiveObservations) {
  LandmarkRegistry map;
  std::mt19937 rng(21);
  const test::TrueLandmark sphere = test::sphere(Eigen::Vector3d(0, 0, 0.3), 0.25);
  const test::TrueLandmark cone =
      test::cone(Eigen::Vector3d(0.3, 0.5, 0.8), -Eigen::Vector3d::UnitZ(), 0.3, 0.5);
  for (int frame = 1; frame <= 4; ++frame) {
    const MapUpdate u = map.integrate(frame, 0.1 * frame, {test::measure(sphere, kCamera, rng)},
                                      kCamera, Matrix6d::Zero());
    EXPECT_TRUE(map.landmarks().empty()) << "frame " << frame;
    ASSERT_EQ(map.candidates().size(), 1u);
    EXPECT_EQ(map.candidates()[0].observations, frame);
    EXPECT_EQ(u.measurements[0].fate,
              frame == 1 ? MeasurementFate::kNewCandidate : MeasurementFate::kCandidate);
    EXPECT_EQ(u.measurements[0].id, map.candidates()[0].id);
  }
  MapUpdate u =
      map.integrate(5, 0.5, {test::measure(sphere, kCamera, rng)}, kCamera, Matrix6d::Zero());
  ASSERT_EQ(map.landmarks().size(), 1u);
  EXPECT_TRUE(map.candidates().empty());
  ASSERT_EQ(u.promoted.size(), 1u);
  const int id = u.promoted[0];
  EXPECT_EQ(u.measurements[0].fate, MeasurementFate::kPromoted);
  EXPECT_EQ(u.measurements[0].id, id);
  ASSERT_EQ(u.promoted_history[0].size(), 5u);
  EXPECT_EQ(u.promoted_history[0].front().frame_index, 1);
  EXPECT_EQ(map.landmark(id).observations, 5);
  EXPECT_DOUBLE_EQ(map.landmark(id).last_observed, 0.5);
  // The landmark is close to the truth (one measurement, 5 mm noise).
  EXPECT_LT((sphereShape(map.landmark(id).quadric_map).center - Eigen::Vector3d(0, 0, 0.3)).norm(),
            0.05);

  // Later frames associate with the same landmark id; a new class starts its own candidate.
  for (int frame = 6; frame <= 15; ++frame) {
    u = map.integrate(frame, 0.1 * frame,
                      {test::measure(sphere, kCamera, rng), test::measure(cone, kCamera, rng)},
                      kCamera, Matrix6d::Zero());
    EXPECT_EQ(u.measurements[0].fate, MeasurementFate::kLandmark);
    EXPECT_EQ(u.measurements[0].id, id);
  }
  EXPECT_EQ(map.landmark(id).observations, 15);
  ASSERT_EQ(map.landmarks().size(), 2u);  // the cone, promoted at its 5th frame (frame 10)
  const int cone_id = std::prev(map.landmarks().end())->first;
  EXPECT_NE(cone_id, id);
  EXPECT_EQ(map.landmark(cone_id).quadric_map.quadricClass(), QuadricClass::kCone);
  EXPECT_EQ(map.landmark(cone_id).observations, 10);  // frames 6..15
  EXPECT_TRUE(map.landmark(cone_id).extent_max.x() > map.landmark(cone_id).extent_min.x());
}

// A spurious detection seen 1..4 times (with gaps shorter than the timeout) never becomes a
// landmark, and expires once unseen for longer than candidate_timeout_frames.
TEST(LandmarkRegistry, DetectionSeenFewerThanFiveTimesNeverEntersAndExpires) {
  for (int times = 1; times <= 4; ++times) {
    LandmarkRegistry::Params p;
    p.candidate_timeout_frames = 3;
    LandmarkRegistry map(p);
    std::mt19937 rng(30 + times);
    const test::TrueLandmark cylinder =
        test::cylinder(Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d::UnitZ(), 0.1, 0.5);
    int frame = 0;
    for (int seen = 0; seen < times; ++seen) {
      ++frame;
      map.integrate(frame, frame * 0.1, {test::measure(cylinder, kCamera, rng)}, kCamera,
                    Matrix6d::Zero());
      ++frame;
      map.integrate(frame, frame * 0.1, {}, kCamera, Matrix6d::Zero());  // a gap
    }
    ASSERT_EQ(map.candidates().size(), 1u) << times;
    int expired = 0;
    for (int i = 0; i < 10; ++i) {
      ++frame;
      expired +=
          map.integrate(frame, frame * 0.1, {}, kCamera, Matrix6d::Zero()).expired_candidates;
    }
    EXPECT_EQ(expired, 1) << times;
    EXPECT_TRUE(map.candidates().empty()) << times;
    EXPECT_TRUE(map.landmarks().empty()) << times;
  }
}

// Ids: fresh per promotion, stable for a landmark, never reused, also after clear().
TEST(LandmarkRegistry, IdsAreStableAndNeverReused) {
  LandmarkRegistry map;
  std::mt19937 rng(40);
  const test::TrueLandmark a = test::sphere(Eigen::Vector3d(0, -0.5, 0.3), 0.2);
  const test::TrueLandmark b = test::sphere(Eigen::Vector3d(0, 0.5, 0.3), 0.2);
  std::vector<int> ids_a, ids_b;
  for (int frame = 1; frame <= 12; ++frame) {
    std::vector<QuadricMeasurement> m = {test::measure(a, kCamera, rng)};
    if (frame >= 3)
      m.push_back(test::measure(b, kCamera, rng));
    const MapUpdate u = map.integrate(frame, frame * 0.1, m, kCamera, Matrix6d::Zero());
    if (frame >= 5)
      ids_a.push_back(u.measurements[0].id);
    if (frame >= 7)
      ids_b.push_back(u.measurements[1].id);
  }
  for (int id : ids_a)
    EXPECT_EQ(id, ids_a.front());
  for (int id : ids_b)
    EXPECT_EQ(id, ids_b.front());
  EXPECT_NE(ids_a.front(), ids_b.front());
  EXPECT_EQ(map.landmark(ids_a.front()).quadric_map.quadricClass(), QuadricClass::kSphere);
  EXPECT_LT(
      (sphereShape(map.landmark(ids_b.front()).quadric_map).center - Eigen::Vector3d(0, 0.5, 0.3))
          .norm(),
      0.05);
  map.clear();
  for (int frame = 13; frame <= 17; ++frame)
    map.integrate(frame, frame * 0.1, {test::measure(a, kCamera, rng)}, kCamera, Matrix6d::Zero());
  ASSERT_EQ(map.landmarks().size(), 1u);
  EXPECT_GT(map.landmarks().begin()->first, std::max(ids_a.front(), ids_b.front()));
}

// A floor the segmenter reports in two fragments every frame: association is one-to-one, so the
// second fragment builds a candidate of its own; at promotion it is the landmark's surface and
// joins it (fate kJoined, its history handed over) instead of becoming a second landmark.
TEST(LandmarkRegistry, CandidateOfALandmarksSurfaceJoinsIt) {
  for (const bool merging : {true, false}) {
    LandmarkRegistry::Params p;
    p.merging.enabled = merging;
    LandmarkRegistry map(p);
    std::mt19937 rng(50);
    const Eigen::Vector3d Z = Eigen::Vector3d::UnitZ(), X = Eigen::Vector3d::UnitX();
    // Two fragments of the floor z = 0 meeting at x = 0.5, each in a frame of its own.
    const test::TrueLandmark near = test::plane(Eigen::Vector3d(0.0, 0, 0), Z, X, 0.5, 1.0);
    const test::TrueLandmark far = test::plane(Eigen::Vector3d(1.02, 0, 0), Z, X, 0.5, 1.0);
    MapUpdate u;
    for (int frame = 1; frame <= 5; ++frame)
      u = map.integrate(frame, 0.1 * frame,
                        {test::measure(near, kCamera, rng), test::measure(far, kCamera, rng)},
                        kCamera, Matrix6d::Zero());
    if (!merging) {
      EXPECT_EQ(u.promoted.size(), 2u);
      EXPECT_EQ(map.landmarks().size(), 2u);
      EXPECT_TRUE(u.joined.empty());
      continue;
    }
    ASSERT_EQ(u.promoted.size(), 1u);
    const int id = u.promoted[0];
    ASSERT_EQ(map.landmarks().size(), 1u);
    ASSERT_EQ(u.joined.size(), 1u);
    EXPECT_EQ(u.joined[0].landmark_id, id);
    EXPECT_EQ(u.joined[0].history.size(), 5u);
    EXPECT_EQ(u.measurements[0].id, id);
    EXPECT_EQ(u.measurements[1].id, id);
    EXPECT_TRUE((u.measurements[0].fate == MeasurementFate::kPromoted) !=
                (u.measurements[1].fate == MeasurementFate::kPromoted));
    EXPECT_TRUE(u.measurements[0].fate == MeasurementFate::kJoined ||
                u.measurements[1].fate == MeasurementFate::kJoined);
    EXPECT_EQ(map.landmark(id).observations, 10);
    // The landmark's extent spans both fragments (world x from -0.5 to 1.52).
    const QuadricLandmark& l = map.landmark(id);
    const ExtentBox world = ExtentBox{l.extent_min, l.extent_max}.transformed(l.quadric_map.pose());
    EXPECT_LT(world.min.x(), -0.45);
    EXPECT_GT(world.max.x(), 1.45);
    EXPECT_TRUE(map.candidates().empty());
  }
}

TEST(LandmarkRegistry, AbsorbedLandmarksAreRecordedWithChainsResolved) {
  LandmarkRegistry map;
  for (int id : {3, 5, 8}) {
    QuadricLandmark l;
    l.id = id;
    l.observations = id;
    map.insertLandmark(l);
  }
  QuadricLandmark survivor = map.landmark(5);
  survivor.observations = 8;
  map.absorbLandmark(3, survivor);
  EXPECT_EQ(map.landmarks().count(3), 0u);
  EXPECT_EQ(map.landmark(5).observations, 8);
  EXPECT_EQ(map.mergedInto(), (std::map<int, int>{{3, 5}}));
  map.absorbLandmark(5, map.landmark(8));
  EXPECT_EQ(map.mergedInto(), (std::map<int, int>{{3, 8}, {5, 8}}));
  EXPECT_THROW(map.absorbLandmark(5, map.landmark(8)), std::out_of_range);
  EXPECT_THROW(map.absorbLandmark(8, map.landmark(8)), std::invalid_argument);
  map.clear();
  EXPECT_TRUE(map.mergedInto().empty());
}

}  // namespace
}  // namespace quadric_slam
