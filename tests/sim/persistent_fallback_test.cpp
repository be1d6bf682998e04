// Adaptive time stepping stops refining a step that needs a collision fallback on the same nodes, at the same
// moment of the step, at several substep lengths in a row (sim/persistent_fallback.hpp).
#include <gtest/gtest.h>

#include "sim/persistent_fallback.hpp"

namespace arcsim {
namespace {

using Nodes = std::vector<std::vector<int>>;

TEST(PersistentFallback, ThreeFirstSubstepFallbacksOnSharedNodesArePersistent) {
  PersistentFallback p(3);
  p.record_failure(0, Nodes{{7, 3, 12}}, 2);
  EXPECT_FALSE(p.persistent());
  p.record_failure(0, Nodes{{12, 40}}, 3);  // shares node 12 (unsorted input)
  EXPECT_FALSE(p.persistent());
  p.record_failure(0, Nodes{{2, 40}}, 4);  // shares node 40 with the attempt before
  EXPECT_TRUE(p.persistent());
  EXPECT_EQ(p.streak(), 3);
  EXPECT_EQ(p.streak_level(), 2);  // where the streak began: the step is retaken there
  EXPECT_EQ(p.streak_nodes(), (Nodes{{2, 3, 7, 12, 40}}));
}

TEST(PersistentFallback, AFallbackAtTheSameMomentOfTheStepAtEveryLengthIsPersistent) {
  // paper-window.json's step 68: substep 1 of 32, 2 of 64, 5 of 128 (each within the one before) all fell back
  // on the same lips.
  PersistentFallback p(3);
  p.record_failure(1, Nodes{{5, 6}}, 5);
  p.record_failure(2, Nodes{{6, 8}}, 6);  // [2/64, 3/64] lies within [1/32, 2/32]
  p.record_failure(5, Nodes{{8}}, 7);     // [5/128, 6/128] lies within [2/64, 3/64]
  EXPECT_TRUE(p.persistent());
  EXPECT_EQ(p.streak_level(), 5);
  EXPECT_EQ(p.streak_nodes(), (Nodes{{5, 6, 8}}));
}

TEST(PersistentFallback, ALaterMomentOrAnotherCauseStartsOver) {
  PersistentFallback p(3);
  p.record_failure(0, Nodes{{1, 2}}, 0);
  p.record_failure(0, Nodes{{2}}, 1);
  p.record_failure(3, Nodes{{2}}, 2);  // [3/4, 1] is not within [0, 1/2]: the length mattered
  EXPECT_EQ(p.streak(), 1);
  EXPECT_EQ(p.streak_level(), 2);
  p.record_failure(0, Nodes{{2}}, 3);  // [0, 1/8] is not within [3/4, 1] either
  EXPECT_EQ(p.streak(), 1);
  p.record_failure(0, Nodes{{}, {}}, 4);  // failed for another reason (no fallback)
  EXPECT_EQ(p.streak(), 0);
  EXPECT_FALSE(p.persistent());
  EXPECT_TRUE(p.streak_nodes().empty());
}

TEST(PersistentFallback, OnlyFinerAttemptsContinueAStreak) {
  PersistentFallback p(3);
  p.record_failure(0, Nodes{{1}}, 3);
  p.record_failure(0, Nodes{{1}}, 4);
  p.record_failure(0, Nodes{{1}}, 4);  // the same level again (a retaken attempt): counted anew
  EXPECT_EQ(p.streak(), 1);
  EXPECT_FALSE(p.persistent());
}

TEST(PersistentFallback, DisjointNodesAreAnotherContact) {
  PersistentFallback p(3);
  p.record_failure(0, Nodes{{1, 2}}, 0);
  p.record_failure(0, Nodes{{2, 5}}, 1);
  p.record_failure(0, Nodes{{8, 9}}, 2);  // a different contact: counted anew
  EXPECT_EQ(p.streak(), 1);
  EXPECT_FALSE(p.persistent());
  // Node numbers only compare within a cloth: cloth 0's node 8 is not cloth 1's.
  p.record_failure(0, Nodes{{}, {8}}, 3);
  EXPECT_EQ(p.streak(), 1);
}

}  // namespace
}  // namespace arcsim
