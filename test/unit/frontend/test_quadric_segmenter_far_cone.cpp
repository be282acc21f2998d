// A cone 2-3 m from the camera under the harsh (real-like) depth model: the generated room at 1 Hz
// for 30 s (seed 1, the sequence of docs/segmentation/README.md). There a cylinder fits the cone's
// visible side about as well as the cone and the normals scatter too much to choose; the segment's
// outline, which widens along the axis (frontend/silhouette_taper.h), decides. Before the outline
// was used the cone was found in 22 of its 29 frames and taken for a cylinder in 5; now 26 and 2.
#include <gtest/gtest.h>

#include <cstdio>
#include <optional>
#include <string>

#include "synth_sequence_score.h"

namespace qs = quadric_slam;

TEST(QuadricSegmenterFarCone, TheRoomsConeIsAConeByItsOutlineAndItsCylinderACylinder) {
  if (qs::test::synthTool().empty())
    GTEST_SKIP() << "the synth tool is not built beside this test";
  const std::optional<qs::SegmentationScore> scored = qs::test::scoreSynthSequence(
      "segmenter_far_cone", qs::test::sceneSequenceArguments("room", 1), 2000);
  ASSERT_TRUE(scored);
  std::printf("%s", scored->report().c_str());
  int cones = 0, cylinders = 0;
  for (const auto& [id, surface] : scored->surfaces()) {
    if (surface.quadric_class == "cylinder") {
      ++cylinders;
      EXPECT_GE(surface.rate(), 0.95) << "surface " << id;
    }
    if (surface.quadric_class != "cone")
      continue;
    ++cones;
    EXPECT_GE(surface.frames_scored, 25) << "the cone is in view most of the sequence";
    EXPECT_GE(surface.rate(), 0.85) << "surface " << id;
  }
  EXPECT_EQ(cones, 1);
  EXPECT_EQ(cylinders, 1);
  EXPECT_LE(scored->spuriousPerFrame(), 0.15);
}
