// A capped tube lying on a desk under the harsh (real-like) depth model: the generated desk's
// poster tube (4 cm radius, 1.2-1.4 m away) at 1 Hz for 30 s with seed 3. CGAL proposes a wide
// cone (0.7 rad) where the support holds the tube and its flat end cap, which the cone's flare
// takes in; the cone fits that support three times better than any cylinder, so the RMS kept it
// (one frame a cone, one dropped as a plane: 28 of 30). Its outline, whose width stays constant
// where the cone's would grow by 0.6 per metre, now rules it out, and the second assignment finds
// the tube's own support: 30 of 30.
#include <gtest/gtest.h>

#include <cstdio>
#include <optional>
#include <string>

#include "synth_sequence_score.h"

namespace qs = quadric_slam;

TEST(QuadricSegmenterLyingTube, TheDesksCappedTubeIsACylinder) {
  if (qs::test::synthTool().empty())
    GTEST_SKIP() << "the synth tool is not built beside this test";
  const std::string scene = std::string(QUADRIC_SLAM_SOURCE_DIR) + "/config/scenes/desk.yaml";
  const std::optional<qs::SegmentationScore> scored = qs::test::scoreSynthSequence(
      "segmenter_lying_tube", "--scene " + scene + " --seconds 30 --rate 1 --no-bag --seed 3",
      2000);
  ASSERT_TRUE(scored);
  std::printf("%s", scored->report().c_str());
  // The generator numbers surfaces in the scene file's order (a box gives six): the tube is 11.
  constexpr int kTube = 11;
  const auto tube = scored->surfaces().find(kTube);
  ASSERT_NE(tube, scored->surfaces().end());
  ASSERT_EQ(tube->second.quadric_class, "cylinder");
  EXPECT_GE(tube->second.frames_scored, 25) << "the tube is in view in most of the sequence";
  EXPECT_GE(tube->second.rate(), 0.95);
  EXPECT_LE(scored->spuriousPerFrame(), 0.3);
}
