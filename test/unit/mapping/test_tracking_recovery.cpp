// What the map does after a loss of tracking (mapping/tracking_recovery.h): localisation only until
// enough consecutive frames anchor the pose on the map's landmarks; nothing to wait for with an
// (almost) empty map.
#include <gtest/gtest.h>

#include <stdexcept>

#include "quadric_slam/mapping/tracking_recovery.h"

using quadric_slam::TrackingRecovery;

TEST(TrackingRecovery, MapsUntilALossThenWaitsForConsecutiveAnchoredFrames) {
  TrackingRecovery::Params params;
  params.relocaliser.enabled = false;  // the counting alone (verification: below)
  params.min_landmark_associations = 3;
  params.confirm_frames = 2;
  TrackingRecovery recovery(params);
  EXPECT_FALSE(recovery.recovering());
  recovery.frameMapped(0);  // mapping as usual: nothing to recover from
  EXPECT_FALSE(recovery.recovering());

  recovery.trackingLost(10);
  EXPECT_TRUE(recovery.recovering());
  EXPECT_EQ(recovery.losses(), 1);
  recovery.trackingLost(10);  // still the same loss
  EXPECT_EQ(recovery.losses(), 1);
  recovery.frameMapped(3);  // one anchored frame ...
  recovery.frameMapped(2);  // ... then too few associations: the count starts again
  recovery.frameMapped(4);
  EXPECT_TRUE(recovery.recovering());
  recovery.frameMapped(5);  // two in a row
  EXPECT_FALSE(recovery.recovering());
  EXPECT_EQ(recovery.recoveries(), 1);
}

TEST(TrackingRecovery, ALossDuringRecoveryRestartsTheCount) {
  TrackingRecovery::Params params;
  params.relocaliser.enabled = false;
  params.confirm_frames = 3;
  TrackingRecovery recovery(params);
  recovery.trackingLost(10);
  recovery.frameMapped(5);
  recovery.frameMapped(5);
  recovery.trackingLost(10);
  recovery.frameMapped(5);
  recovery.frameMapped(5);
  EXPECT_TRUE(recovery.recovering());
  recovery.frameMapped(5);
  EXPECT_FALSE(recovery.recovering());
}

TEST(TrackingRecovery, AnAlmostEmptyMapHasNothingToWaitFor) {
  TrackingRecovery::Params params;
  params.min_map_landmarks = 3;
  TrackingRecovery recovery(params);
  recovery.trackingLost(2);
  EXPECT_FALSE(recovery.recovering());
  EXPECT_EQ(recovery.losses(), 0);
}

TEST(TrackingRecovery, GivesUpAfterMaxFramesWhenAsked) {
  TrackingRecovery::Params params;
  params.max_frames = 4;
  TrackingRecovery recovery(params);
  recovery.trackingLost(10);
  for (int i = 0; i < 3; ++i)
    recovery.frameMapped(0);
  EXPECT_TRUE(recovery.recovering());
  recovery.frameMapped(0);
  EXPECT_FALSE(recovery.recovering());
  EXPECT_EQ(recovery.timeouts(), 1);
  EXPECT_EQ(recovery.recoveries(), 0);
  params.max_frames = 0;  // the default waits
  TrackingRecovery waiting(params);
  waiting.trackingLost(10);
  for (int i = 0; i < 1000; ++i)
    waiting.frameMapped(0);
  EXPECT_TRUE(waiting.recovering());
}

TEST(TrackingRecovery, BadParametersAreNamed) {
  TrackingRecovery::Params params;
  params.confirm_frames = 0;
  try {
    TrackingRecovery recovery(params);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("confirm_frames"), std::string::npos) << e.what();
  }
  params = {};
  params.min_landmark_associations = 0;
  EXPECT_THROW(TrackingRecovery{params}, std::invalid_argument);
}

// With relocalisation enabled, associations count only once the relocaliser has found the pose
// since the loss (a floor and two walls also associate at a wrong pose); a new loss asks again.
TEST(TrackingRecovery, WithRelocalisationFramesAnchorOnlyAfterThePoseIsConfirmed) {
  TrackingRecovery::Params params;
  params.confirm_frames = 2;
  TrackingRecovery recovery(params);
  recovery.trackingLost(10);
  EXPECT_FALSE(recovery.poseVerified());
  recovery.frameMapped(8);
  recovery.frameMapped(8);
  recovery.frameMapped(8);
  EXPECT_TRUE(recovery.recovering()) << "resumed on associations the relocaliser never confirmed";
  recovery.relocalisationAttempted(/*found=*/false, /*reanchored=*/false);
  recovery.frameMapped(8);
  recovery.frameMapped(8);
  EXPECT_TRUE(recovery.recovering());
  recovery.relocalisationAttempted(/*found=*/true, /*reanchored=*/true);
  EXPECT_TRUE(recovery.poseVerified());
  recovery.frameMapped(8);
  EXPECT_TRUE(recovery.recovering());
  recovery.frameMapped(8);
  EXPECT_FALSE(recovery.recovering());
  EXPECT_EQ(recovery.relocalisationAttempts(), 2);
  EXPECT_EQ(recovery.relocalisations(), 1);
  recovery.trackingLost(10);
  EXPECT_FALSE(recovery.poseVerified()) << "a new loss needs a new confirmation";
}

TEST(TrackingRecovery, RelocaliserParametersAreValidated) {
  TrackingRecovery::Params params;
  params.relocaliser.max_ambiguity = 1.5;
  EXPECT_THROW(TrackingRecovery{params}, std::invalid_argument);
}

// A recovery that began with a promotion at the loss (the map's first landmarks, made from the
// candidates of the frames before it) gives up after promoted_max_frames, whatever max_frames
// says: those few surfaces may never come into view again. A later loss waits as configured.
TEST(TrackingRecovery, ARecoveryOnLandmarksPromotedAtTheLossGivesUpAfterItsOwnLimit) {
  TrackingRecovery::Params params;
  params.max_frames = 0;  // wait for ever after an ordinary loss
  params.promoted_max_frames = 5;
  TrackingRecovery recovery(params);
  recovery.trackingLost(4, /*promoted_at_loss=*/true);
  ASSERT_TRUE(recovery.recovering());
  for (int i = 0; i < 4; ++i)
    recovery.frameMapped(0);
  EXPECT_TRUE(recovery.recovering());
  recovery.frameMapped(0);
  EXPECT_FALSE(recovery.recovering());
  EXPECT_EQ(recovery.timeouts(), 1);

  recovery.trackingLost(10);
  for (int i = 0; i < 100; ++i)
    recovery.frameMapped(0);
  EXPECT_TRUE(recovery.recovering()) << "an ordinary loss took the promoted limit";
}

TEST(TrackingRecovery, PromotionParametersAreValidated) {
  TrackingRecovery::Params params;
  params.promote_on_loss_min_observations = -1;
  EXPECT_THROW(TrackingRecovery{params}, std::invalid_argument);
  params = {};
  params.promoted_max_frames = 0;
  EXPECT_THROW(TrackingRecovery{params}, std::invalid_argument);
}
