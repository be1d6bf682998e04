// Adaptive time stepping stops refining a step whose first substep needs a collision fallback on the same nodes
// at several substep lengths in a row (sim/persistent_fallback.hpp).
#include <gtest/gtest.h>

#include "sim/persistent_fallback.hpp"

namespace arcsim {
namespace {

using Nodes = std::vector<std::vector<int>>;

TEST(PersistentFallback, ThreeFirstSubstepFallbacksOnSharedNodesArePersistent) {
  PersistentFallback p(3);
  p.record_failure(0, Nodes{{7, 3, 12}});
  EXPECT_FALSE(p.persistent());
  p.record_failure(0, Nodes{{12, 40}});  // shares node 12 (unsorted input)
  EXPECT_FALSE(p.persistent());
  p.record_failure(0, Nodes{{2, 40}});  // shares node 40 with the attempt before
  EXPECT_TRUE(p.persistent());
  EXPECT_EQ(p.streak(), 3);
}

TEST(PersistentFallback, ALaterSubstepOrAnotherCauseStartsOver) {
  PersistentFallback p(3);
  p.record_failure(0, Nodes{{1, 2}});
  p.record_failure(0, Nodes{{2}});
  p.record_failure(3, Nodes{{2}});  // failed later in the step: the length mattered
  EXPECT_EQ(p.streak(), 0);
  p.record_failure(0, Nodes{{2}});
  p.record_failure(0, Nodes{{}, {}});  // failed for another reason (no fallback)
  EXPECT_EQ(p.streak(), 0);
  EXPECT_FALSE(p.persistent());
}

TEST(PersistentFallback, DisjointNodesAreAnotherContact) {
  PersistentFallback p(3);
  p.record_failure(0, Nodes{{1, 2}});
  p.record_failure(0, Nodes{{2, 5}});
  p.record_failure(0, Nodes{{8, 9}});  // a different contact: counted anew
  EXPECT_EQ(p.streak(), 1);
  EXPECT_FALSE(p.persistent());
  // Node numbers only compare within a cloth: cloth 0's node 8 is not cloth 1's.
  p.record_failure(0, Nodes{{}, {8}});
  EXPECT_EQ(p.streak(), 1);
}

}  // namespace
}  // namespace arcsim
