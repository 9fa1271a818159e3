// sort_indices against std::sort on the shapes the builder sorts: appended
// tails, shuffled lists of every size around the method switches, duplicates,
// large indices (several radix passes), already sorted and reversed lists.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include <icd/mesh/spheres/sort_indices.hpp>

namespace {

void expect_sorted_like_std(std::vector<int> v) {
  std::vector<int> expected = v;
  std::sort(expected.begin(), expected.end());
  icd::mesh::sort_indices(v);
  ASSERT_EQ(v, expected);
}

TEST(SortIndices, EqualsStdSortOnEveryShape) {
  std::mt19937 rng(11);
  for (int n : {0, 1, 2, 7, 100, 1023, 1024, 1025, 5000, 70000}) {
    for (int largest : {3, 1000, 2047, 2048, 1 << 22, (1 << 30) + 12345}) {
      std::uniform_int_distribution<int> value(0, largest);
      std::vector<int> v(static_cast<size_t>(n));
      for (int& x : v) x = value(rng);
      expect_sorted_like_std(v);  // shuffled, with duplicates when largest < n
      std::sort(v.begin(), v.end());
      expect_sorted_like_std(v);  // already sorted
      std::vector<int> reversed(v.rbegin(), v.rend());
      expect_sorted_like_std(reversed);
      for (int k = 0; k < n / 20 + 1; ++k) v.push_back(value(rng));  // appended tail
      expect_sorted_like_std(v);
    }
  }
}

}  // namespace
