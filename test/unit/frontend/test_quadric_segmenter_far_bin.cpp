// A cylinder's narrow strip 1.8-2.2 m away at the image's edge under the harsh (real-like) depth
// model: the open waste bin of the generated desk at 1 Hz for 30 s (seed 1, the sequence of
// docs/segmentation/README.md), found in 4 of its 11 frames before two changes:
// - the correlated noise bends the strip so that a general quadric fits it with a third less RMS
//   by its first-order (Sampson) distance, which made the shape test drop the cylinder; along the
//   rays, where the sensor errs, that quadric explains the depths no better (a tenth to a quarter
//   of the rays miss it), and the cylinder stays (frontend/ray_residual.h): 10 of 11;
// - in the last frame CGAL took the strip for planes (their support, the points within its 8 mm
//   epsilon, flatters them where the noise is larger); the cylinder the bending normals describe
//   fits within plane_rms_ratio of such a plane and is verified as a candidate: 11 of 11.
#include <gtest/gtest.h>

#include <cstdio>
#include <optional>
#include <string>

#include "synth_sequence_score.h"

namespace qs = quadric_slam;

TEST(QuadricSegmenterFarBin, TheDesksOpenBinIsACylinder) {
  if (qs::test::synthTool().empty())
    GTEST_SKIP() << "the synth tool is not built beside this test";
  const std::optional<qs::SegmentationScore> scored = qs::test::scoreSynthSequence(
      "segmenter_far_bin", qs::test::sceneSequenceArguments("desk", 1), 2000);
  ASSERT_TRUE(scored);
  std::printf("%s", scored->report().c_str());
  // The generator numbers surfaces in the scene file's order (a box gives six): the bin is 23, in
  // view in a third of the sequence.
  qs::test::expectSurfaceFound(*scored, 23, "cylinder", 10, 0.85);
  EXPECT_LE(scored->spuriousPerFrame(), 0.3);
}
