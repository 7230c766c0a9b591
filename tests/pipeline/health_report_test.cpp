// The run's health report: which map segments were never found in the map.
#include <gtest/gtest.h>

#include "taiga/pipeline/run.hpp"

namespace taiga::pipeline {
namespace {

TEST(HealthReport, ASegmentBetweenTwoTiedOnesFloatsAndTheTrackCountsAsLost) {
  HealthReport h;
  EXPECT_TRUE(h.floatingSegments().empty());
  EXPECT_FALSE(h.trackLost());
  // Segment 1 (an open field) was never found; segment 2 re-attached to the map.
  h.map_segments = 3;
  h.reattached.push_back({.segment = 2});
  EXPECT_EQ(h.floatingSegments(), (std::vector<std::uint64_t>{1}));
  EXPECT_TRUE(h.trackLost());
  EXPECT_EQ(h.verdict(), "lost");
  h.reattached.push_back({.segment = 1});
  EXPECT_TRUE(h.floatingSegments().empty());
  EXPECT_FALSE(h.trackLost());
}

}  // namespace
}  // namespace taiga::pipeline
