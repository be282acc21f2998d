#include <gtest/gtest.h>

#include <stdexcept>
#include <utility>
#include <vector>

#include "quadric_slam/io/stamp_association.h"

using quadric_slam::associateStamps;
using quadric_slam::StampAssociationParams;
using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;

TEST(StampAssociation, GreedyByDifferenceEachStampOnce) {
  // second[0] = 1.005 is closest to first[0] = 1.0 (0.005) and to first[1] = 1.006 (0.001): the
  // smaller difference wins, so first[0] falls back to second[1] = 0.99 (0.01).
  const std::vector<double> first = {1.0, 1.006, 2.0, 3.0};
  const std::vector<double> second = {1.005, 0.99, 2.05, 2.99, 3.011};
  const Pairs matches = associateStamps(first, second, StampAssociationParams{});
  EXPECT_EQ(matches, (Pairs{{0, 1}, {1, 0}, {3, 3}}));
}

TEST(StampAssociation, StrictLimitAndOffset) {
  StampAssociationParams params;
  params.max_difference = 0.25;  // exactly representable: a difference of 0.25 is not < 0.25
  EXPECT_TRUE(associateStamps({1.0}, {1.25}, params).empty());
  EXPECT_EQ(associateStamps({1.0}, {1.125}, params), (Pairs{{0, 0}}));
  params.offset = 10.0;  // second stamps are shifted by +10 s before comparing
  EXPECT_EQ(associateStamps({11.0, 12.0}, {2.0, 1.0}, params), (Pairs{{0, 1}, {1, 0}}));
}

TEST(StampAssociation, ValidateNamesTheField) {
  StampAssociationParams params;
  params.max_difference = 0.0;
  try {
    params.validate();
    FAIL() << "expected invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_difference"), std::string::npos);
  }
}
