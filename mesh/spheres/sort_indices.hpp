#pragma once
/// Sorting lists of sample indices (non-negative ints) in increasing order,
/// the builder's most frequent sort. The result is the one std::sort gives
/// (a sorted list of ints is unique), so trees do not change; only the time.
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

namespace icd::mesh {

/// Sorts `v` (every entry >= 0) in increasing order. A list that is already
/// sorted costs one scan; one whose unsorted tail is short (entries appended
/// to a sorted list) sorts the tail and merges it; a long list is sorted by
/// radix (11 bits per pass, as many passes as its largest entry needs).
inline void sort_indices(std::vector<int>& v) {
  const auto unsorted = std::is_sorted_until(v.begin(), v.end());
  if (unsorted == v.end()) return;
  const std::size_t n = v.size();
  const std::size_t tail = static_cast<std::size_t>(v.end() - unsorted);
  if (tail * 8 < n) {
    std::sort(unsorted, v.end());
    std::inplace_merge(v.begin(), unsorted, v.end());
    return;
  }
  if (n < 1024) {
    std::sort(v.begin(), v.end());
    return;
  }
  const unsigned largest = static_cast<unsigned>(*std::max_element(v.begin(), v.end()));
  constexpr int kBits = 11;
  constexpr unsigned kMask = (1u << kBits) - 1;
  std::vector<int> scratch(n);
  std::vector<int>* from = &v;
  std::vector<int>* to = &scratch;
  for (int shift = 0; shift == 0 || (largest >> shift) != 0; shift += kBits) {
    std::array<std::size_t, (1u << kBits) + 1> start{};
    for (int x : *from) ++start[((static_cast<unsigned>(x) >> shift) & kMask) + 1];
    for (std::size_t d = 1; d < start.size(); ++d) start[d] += start[d - 1];
    for (int x : *from) (*to)[start[(static_cast<unsigned>(x) >> shift) & kMask]++] = x;
    std::swap(from, to);
  }
  if (from != &v) v.swap(*from);
}

}  // namespace icd::mesh
