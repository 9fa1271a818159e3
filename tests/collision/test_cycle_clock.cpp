#include <gtest/gtest.h>

#include <icd/collision/cycle_clock.hpp>

namespace icd::collision {
namespace {

TEST(CycleClock, CalibratedAndMonotonic) {
  if (!has_cycle_counter()) GTEST_SKIP() << "no cycle counter on this architecture";
  const uint64_t a = read_cycle_counter(), b = read_cycle_counter();
  EXPECT_LE(a, b);
  // Any real processor counts between 10 MHz and 100 GHz.
  EXPECT_GT(cycle_counter_hz(), 1e7);
  EXPECT_LT(cycle_counter_hz(), 1e11);
  EXPECT_EQ(cycle_counter_hz(), cycle_counter_hz());  // measured once
}

}  // namespace
}  // namespace icd::collision
