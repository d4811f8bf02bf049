// EdgeMap (the adjacency's half-edges, the plugin's per-edge books) against std::map under
// random inserts, overwrites, counted updates and erasures, including erasures with stale values
// and runs that wrap around the end of the table (backward-shift deletion must keep every
// remaining key findable).
#include "conform/mesh/adjacency.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <utility>

using conform::mesh::EdgeMap;

TEST(EdgeMap, EmptyFindsNothingAndErasesNothing) {
  EdgeMap t;
  EXPECT_EQ(t.find(1, 2), EdgeMap::kNone);
  t.erase(1, 2, 0);
  EXPECT_EQ(t.size(), 0u);
}

TEST(EdgeMap, InsertKeepsOrOverwritesAndAtCounts) {
  EdgeMap t;
  EXPECT_TRUE(t.insert(3, 4, 7));
  EXPECT_FALSE(t.insert(3, 4, 8));
  EXPECT_EQ(t.find(3, 4), 7);
  EXPECT_TRUE(t.insert(3, 4, 8, true));
  EXPECT_EQ(t.find(3, 4), 8);
  EXPECT_EQ(t.find(4, 3), EdgeMap::kNone);  // directed keys
  ++t.at(5, 6, 0);
  ++t.at(5, 6, 0);
  EXPECT_EQ(t.find(5, 6), 2);
  t.erase(5, 6, 1);  // stale value: kept
  EXPECT_EQ(t.find(5, 6), 2);
  t.erase(5, 6, 2);
  EXPECT_EQ(t.find(5, 6), EdgeMap::kNone);
  EXPECT_EQ(t.size(), 1u);
}

TEST(EdgeMap, MatchesAMapUnderRandomEdits) {
  for (const int range : {8, 60, 3000}) {  // dense keys (long runs, wrap-around) to sparse
    EdgeMap t;
    std::map<std::pair<int, int>, int> ref;
    std::mt19937 rng{std::uint32_t(range)};
    for (int step = 0; step < 40000; ++step) {
      const int u = int(rng() % std::uint32_t(range)), v = int(rng() % std::uint32_t(range));
      const auto k = std::make_pair(u, v);
      switch (rng() % 4) {
        case 0: {
          const int value = int(rng() % 100);
          const bool fresh = !ref.count(k);
          ASSERT_EQ(t.insert(u, v, value), fresh);
          if (fresh) ref[k] = value;
          break;
        }
        case 1: {
          const int value = int(rng() % 100);
          t.insert(u, v, value, true);
          ref[k] = value;
          break;
        }
        case 2:
          ++t.at(u, v, 0);
          ++ref[k];
          break;
        default: {
          auto it = ref.find(k);
          const int value = it == ref.end() ? 0 : (rng() % 2 ? it->second : it->second + 1);
          t.erase(u, v, value);
          if (it != ref.end() && it->second == value) ref.erase(it);
        }
      }
      if (step % 997 == 0) {
        for (const auto& [key, value] : ref) ASSERT_EQ(t.find(key.first, key.second), value);
      }
      ASSERT_EQ(t.size(), ref.size());
    }
    for (int u = 0; u < std::min(range, 60); ++u) {
      for (int v = 0; v < std::min(range, 60); ++v) {
        auto it = ref.find({u, v});
        ASSERT_EQ(t.find(u, v), it == ref.end() ? EdgeMap::kNone : it->second);
      }
    }
  }
}
