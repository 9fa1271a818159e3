#include <icd/collision/traversal.hpp>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <string>
#include <type_traits>

#include <icd/collision/cycle_clock.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::collision {
namespace {

using Clock = std::chrono::steady_clock;

// Every child of the node split next may be tested (see WorkPair::allowed).
constexpr uint32_t kAllChildren = ~uint32_t{0};
constexpr int32_t kMaskedChildren = 31;  // children a mask can rule out

// A pair being refined. `split_b`: the node to split next is b (the paper's
// p.2); the flag flips at every generated pair, which is Fig. 7's swap.
// `allowed`: bit j set when child j of the node split next may overlap (with
// CollisionRequest::parent_filter: it overlaps the node the pair's other node
// was split from); children past the 31st are always allowed.
struct WorkPair {
  int32_t a;
  int32_t b;
  int32_t split_b;
  uint32_t allowed;
};

inline WorkPair work_pair(int32_t a, int32_t b, bool split_b, uint32_t allowed = kAllChildren) {
  return {a, b, split_b ? 1 : 0, allowed};
}

inline bool is_allowed(uint32_t allowed, int32_t j) {
  return j >= kMaskedChildren || ((allowed >> j) & 1u);
}

// The allowed ones of the first n <= 64 children, as bits.
inline uint64_t allowed_children(uint32_t allowed, int32_t n) {
  const uint64_t all = n == 64 ? ~uint64_t{0} : (uint64_t{1} << n) - 1;
  return all & (allowed | ~((uint64_t{1} << kMaskedChildren) - 1));
}

// Growable ring buffer (FIFO), storage kept between queries of a thread.
class PairQueue {
 public:
  void clear() { m_head = m_size = 0; }
  bool empty() const { return m_size == 0; }
  std::size_t size() const { return m_size; }
  void push(const WorkPair& p) {
    if (m_size == m_buf.size()) grow();
    m_buf[(m_head + m_size) & m_mask] = p;
    ++m_size;
  }
  WorkPair pop() {
    const WorkPair p = m_buf[m_head];
    m_head = (m_head + 1) & m_mask;
    --m_size;
    return p;
  }
  /// Room for `extra` more pairs without growing.
  void ensure(std::size_t extra) {
    while (m_size + extra > m_buf.size()) grow();
  }
  /// Branch-free conditional push (after ensure()).
  void push_if(const WorkPair& p, bool keep) {
    m_buf[(m_head + m_size) & m_mask] = p;
    m_size += keep;
  }
  template <class F>
  void for_each(F&& f) const {
    for (std::size_t k = 0; k < m_size; ++k) f(m_buf[(m_head + k) & m_mask]);
  }
  /// Raw appends (after ensure()): write pair k of the batch at
  /// raw()[(tail() + k) & mask()], then commit(count).
  WorkPair* raw() { return m_buf.data(); }
  std::size_t tail() const { return m_head + m_size; }
  std::size_t mask() const { return m_mask; }
  void commit(std::size_t count) { m_size += count; }
  /// State access for the hot loop (run_plain_fifo), which keeps head and
  /// size in registers and writes them back before anything else runs.
  std::size_t head() const { return m_head; }
  std::size_t capacity() const { return m_buf.size(); }
  void set_state(std::size_t head, std::size_t size) {
    m_head = head;
    m_size = size;
  }
  /// Applies f to the last `count` pairs pushed.
  template <class F>
  void for_last(std::size_t count, F&& f) {
    for (std::size_t k = m_size - count; k < m_size; ++k) f(m_buf[(m_head + k) & m_mask]);
  }

 private:
  void grow() {
    const std::size_t cap = std::max<std::size_t>(1024, 2 * m_buf.size());
    std::vector<WorkPair> nb(cap);
    for (std::size_t k = 0; k < m_size; ++k) nb[k] = m_buf[(m_head + k) & m_mask];
    m_buf.swap(nb);
    m_head = 0;
    m_mask = cap - 1;
  }
  std::vector<WorkPair> m_buf;
  std::size_t m_head = 0, m_size = 0, m_mask = 0;
};

// LIFO with the same interface.
class PairStack {
 public:
  void clear() { m_size = 0; }
  bool empty() const { return m_size == 0; }
  std::size_t size() const { return m_size; }
  void push(const WorkPair& p) {
    ensure(1);
    m_buf[m_size++] = p;
  }
  WorkPair pop() { return m_buf[--m_size]; }
  void ensure(std::size_t extra) {
    if (m_size + extra > m_buf.size())
      m_buf.resize(std::max<std::size_t>(1024, 2 * (m_size + extra)));
  }
  void push_if(const WorkPair& p, bool keep) {
    m_buf[m_size] = p;
    m_size += keep;
  }
  template <class F>
  void for_each(F&& f) const {
    for (std::size_t k = m_size; k-- > 0;) f(m_buf[k]);
  }
  WorkPair* raw() { return m_buf.data(); }
  std::size_t tail() const { return m_size; }
  std::size_t mask() const { return ~std::size_t{0}; }
  void commit(std::size_t count) { m_size += count; }
  template <class F>
  void for_last(std::size_t count, F&& f) {
    for (std::size_t k = m_size - count; k < m_size; ++k) f(m_buf[k]);
  }

 private:
  std::vector<WorkPair> m_buf;
  std::size_t m_size = 0;
};

// Seconds to copy one pending pair into the result at an interruption,
// measured once (copying 64k pairs, best of 5), at least 0.3 ns.
double output_seconds_per_pair() {
  static const double cost = [] {
    constexpr std::size_t n = 1 << 16;
    std::vector<WorkPair> src(n, work_pair(1, 2, false));
    std::vector<NodePair> dst;
    dst.reserve(n);
    double best = 1.0;
    for (int rep = 0; rep < 5; ++rep) {
      dst.clear();
      const auto t0 = Clock::now();
      for (const WorkPair& p : src) dst.push_back({p.a, p.b});
      const auto t1 = Clock::now();
      best = std::min(best, std::chrono::duration<double>(t1 - t0).count() / n);
    }
    return std::max(best, 0.3e-9);
  }();
  return cost;
}

// Per-pair cost of finishing an interrupted query (copying the pending pairs,
// computing completed_level), learnt from the interrupted queries of this
// thread, starting from the calibrated copy cost.
thread_local double t_finish_cost = 0.0;

// Budget: one integer compare per sphere test; the clock is read only every
// `interval` tests.
class Budget {
 public:
  Budget(const CollisionRequest& r, Clock::time_point start)
      : m_max_tests(r.budget_tests < 0 ? INT64_MAX : r.budget_tests) {
    m_timed = std::isfinite(r.budget_seconds);
    m_interval = r.clock_check_interval;
    if (m_timed) {
      if (r.clock == ClockSource::CycleCounter && has_cycle_counter()) {
        m_use_tsc = true;
        const double hz = cycle_counter_hz();
        // Measured from the query's start on the steady clock, mapped to cycles.
        const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
        m_tsc_deadline = read_cycle_counter() +
                         static_cast<uint64_t>(std::max(0.0, r.budget_seconds - elapsed) * hz);
      } else {
        m_deadline = start + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(r.budget_seconds));
      }
    }
    m_next = m_timed ? 0 : m_max_tests;  // a timed query reads the clock before its first test
  }
  // True when tests number `tests` .. `tests + count - 1` trigger no budget
  // event (no clock read due, test budget not reached): they may run unchecked.
  bool batch_ok(int64_t tests, int64_t count) const { return tests + count <= m_next; }
  // The test number at which the next budget event falls (see batch_ok).
  int64_t next_event() const { return m_next; }

  // Call before test number `tests` with `pending` pairs that an interruption
  // would have to copy out; returns false (and sets the reason) to stop. The
  // time to copy the pending pairs is reserved out of the budget.
  inline bool allow(int64_t tests, std::size_t pending, StopReason& reason) {
    if (tests != m_next) [[likely]]
      return true;
    return slow(tests, pending, reason);
  }

 private:
  bool slow(int64_t tests, std::size_t pending, StopReason& reason) {
    if (tests >= m_max_tests) {
      reason = StopReason::TestBudget;
      return false;
    }
    if (m_timed) {
      const double reserve = static_cast<double>(pending) * t_finish_cost;
      const bool expired =
          m_use_tsc ? read_cycle_counter() + static_cast<uint64_t>(reserve * cycle_counter_hz()) >=
                          m_tsc_deadline
                    : Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                         std::chrono::duration<double>(reserve)) >=
                          m_deadline;
      if (expired) {
        reason = StopReason::TimeBudget;
        m_stopped_at = Clock::now();
        return false;
      }
      m_next = std::min<int64_t>(tests + m_interval, m_max_tests);
    } else {
      m_next = m_max_tests;
    }
    return true;
  }

 public:
  Clock::time_point m_stopped_at{};  ///< when a time stop was decided

 private:
  int64_t m_max_tests;
  int64_t m_next = 0;
  bool m_timed = false, m_use_tsc = false;
  int m_interval = 1;
  Clock::time_point m_deadline;
  uint64_t m_tsc_deadline = 0;
};

inline double penetration(const Sphere& p, const Sphere& q) {
  const double dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
  return p.r + q.r - std::sqrt(dx * dx + dy * dy + dz * dz);
}

struct Trees {
  const Sphere* sa;
  const Sphere* sb;
  const int32_t* fca;
  const int32_t* cca;
  const int32_t* fcb;
  const int32_t* ccb;
  const int32_t* la;
  const int32_t* lb;
  int cap;
  bool parent_filter;
  bool uncapped;  // cap deeper than both trees: expandable == has children
  bool expandable_a(int32_t n) const { return cca[n] > 0 && la[n] < cap; }
  bool expandable_b(int32_t n) const { return ccb[n] > 0 && lb[n] < cap; }
  bool overlaps(int32_t a, int32_t b) const { return overlap(sa[a], sb[b]); }
};

// Where a known-overlapping pair goes when it cannot be split further.
inline void settle(const Trees& t, int32_t a, int32_t b, CollisionResult& res) {
  if (t.cca[a] == 0 && t.ccb[b] == 0)
    res.colliding.push_back({a, b});
  else
    res.untested.push_back({a, b});  // held back by depth_cap
}

// Chooses the node to split of an overlapping pair per Fig. 7: split b if
// `split_b` and b is expandable, otherwise a (the swap for a leaf).
inline bool choose_split_b(const Trees& t, const WorkPair& p) {
  const bool eb = t.expandable_b(p.b);
  return p.split_b ? eb : !t.expandable_a(p.a) && eb;
}

// One split: the children [first, end) of one node of `p` (b's when
// `split_b`) against the other node, `other`. The pairs it queues split
// `other` next when it is expandable (Fig. 7's swap).
struct Split {
  bool split_b;
  int32_t first, end;
  int32_t other;
  bool other_expandable;
  bool next_split_b;
  Split(const Trees& t, const WorkPair& p) {
    split_b = choose_split_b(t, p);
    first = split_b ? t.fcb[p.b] : t.fca[p.a];
    end = first + (split_b ? t.ccb[p.b] : t.cca[p.a]);
    other = split_b ? p.a : p.b;
    other_expandable = split_b ? t.expandable_a(p.a) : t.expandable_b(p.b);
    next_split_b = !split_b;
  }
  // Tests of the parent filter for this split: other's children (the first
  // 31) against the split node; 0 when the filter is off or other will not be
  // split.
  int32_t filter_tests(const Trees& t) const {
    if (!t.parent_filter || !other_expandable) return 0;
    return std::min<int32_t>(split_b ? t.cca[other] : t.ccb[other], kMaskedChildren);
  }
};

// The parent filter makes a mask only for a split that queues at least this
// many pairs: for one pair the mask's tests cost about what they save.
// Measured (contact_tightness, 400 approach poses of two dragons 1 unit short
// of touching, three trees): 5-6 % fewer sphere tests than with a mask for
// every split, 1-3 % more leaf pairs.
constexpr std::size_t kMaskFromPairs = 2;

// The parent filter's tests of one split: the other node's children (the
// first 31; later ones are always allowed) against the split node. Bit j of
// the mask: child j overlaps it.
struct FilterTests {
  Sphere split;
  const Sphere* kids;  // the other node's first child
  int32_t count;
  FilterTests(const Trees& t, const Split& s, const WorkPair& p)
      : split(s.split_b ? t.sb[p.b] : t.sa[p.a]),
        kids(s.split_b ? t.sa + t.fca[s.other] : t.sb + t.fcb[s.other]),
        count(s.filter_tests(t)) {}
  uint32_t bit(int32_t j) const { return static_cast<uint32_t>(overlap(split, kids[j])) << j; }
  // The whole mask, its tests counted (no budget event may fall inside).
  uint32_t mask(CollisionResult& res) const {
    uint32_t m = 0;
    for (int32_t j = 0; j < count; ++j) m |= bit(j);
    res.tests += count;
    return m;
  }
};

// Tests the allowed children of the split node against the other node one at
// a time, each under the budget: an overlapping pair that can be split further
// goes to `queue(WorkPair)`, one that cannot is settled; children the parent
// filter rules out count as pruned. When the filter may make a mask, the
// overlapping pairs among the first 64 children are held back (as bits) until
// the other node's children have been tested against the split node (under
// the budget too). `pending()` is the current size of the work list (for the
// budget's reserve). Returns false when the budget stopped it (the untested
// children are then reported; pairs held back are queued with every child
// allowed).
template <class PendingSize, class Queue>
bool test_children_one_by_one(const Trees& t, const WorkPair& p, const Split& s, Budget& budget,
                              bool record_front, CollisionResult& res, PendingSize pending,
                              Queue queue) {
  StopReason reason = StopReason::Completed;
  const bool may_mask = s.filter_tests(t) > 0;
  uint64_t held = 0;  // bit k: child first + k overlaps and waits for the mask
  std::size_t num_held = 0, num_queued = 0;  // queued: held or not
  auto pair_of = [&](int32_t c) { return s.split_b ? NodePair{p.a, c} : NodePair{c, p.b}; };
  auto flush = [&](uint32_t mask) {
    for (uint64_t bits = held; bits != 0; bits &= bits - 1) {
      const NodePair q = pair_of(s.first + std::countr_zero(bits));
      queue(work_pair(q.a, q.b, s.next_split_b, mask));
    }
  };
  for (int32_t c = s.first; c < s.end; ++c) {
    const NodePair q = pair_of(c);
    if (!is_allowed(p.allowed, c - s.first)) {  // misses the other side's parent
      if (record_front) res.front.push_back(q);
      continue;
    }
    if (!budget.allow(res.tests, pending() + num_held, reason)) {
      for (int32_t r = c; r < s.end; ++r) {
        if (is_allowed(p.allowed, r - s.first))
          res.untested.push_back(pair_of(r));
        else if (record_front)
          res.front.push_back(pair_of(r));  // pruned by the filter: still part of the cut
      }
      flush(kAllChildren);
      res.interrupted = true;
      res.stop_reason = reason;
      return false;
    }
    ++res.tests;
    if (!t.overlaps(q.a, q.b)) {
      if (record_front) res.front.push_back(q);
      continue;
    }
    if (!t.expandable_a(q.a) && !t.expandable_b(q.b)) {
      settle(t, q.a, q.b, res);
    } else if (may_mask && c - s.first < 64) {
      held |= uint64_t{1} << (c - s.first);
      ++num_held, ++num_queued;
    } else {
      queue(work_pair(q.a, q.b, s.next_split_b));
      ++num_queued;
    }
  }
  if (!may_mask || num_queued < kMaskFromPairs) {
    flush(kAllChildren);
    return true;
  }
  const FilterTests f(t, s, p);
  uint32_t mask = 0;
  for (int32_t j = 0; j < f.count; ++j) {
    if (!budget.allow(res.tests, pending() + num_held, reason)) {
      flush(kAllChildren);  // stopped: the pairs are reported unrefined anyway
      res.interrupted = true;
      res.stop_reason = reason;
      return false;
    }
    ++res.tests;
    mask |= f.bit(j);
  }
  flush(mask);
  return true;
}

// Literal Fig. 7 (and Fig. 4 with a stack): pairs are tested when popped.
template <class List>
void run_literal(const Trees& t, List& list, Budget& budget, bool record_front,
                 CollisionResult& res) {
  StopReason reason = StopReason::Completed;
  while (!list.empty()) {
    if (!budget.allow(res.tests, list.size(), reason)) {
      res.interrupted = true;
      res.stop_reason = reason;
      break;
    }
    const WorkPair p = list.pop();
    ++res.tests;
    if (!t.overlaps(p.a, p.b)) {
      if (record_front) res.front.push_back({p.a, p.b});
      continue;
    }
    const bool ea = t.expandable_a(p.a), eb = t.expandable_b(p.b);
    if (!ea && !eb) {
      settle(t, p.a, p.b, res);
      continue;
    }
    const bool split2_is_b = p.split_b != 0;
    const bool split2_expandable = split2_is_b ? eb : ea;
    if (!split2_expandable) {  // p.2 is a leaf, p.1 is not: push the swapped pair
      list.push(work_pair(p.a, p.b, !p.split_b));
    } else if (split2_is_b) {
      for (int32_t c = t.fcb[p.b], e = c + t.ccb[p.b]; c < e; ++c)
        list.push(work_pair(p.a, c, false));
    } else {
      for (int32_t c = t.fca[p.a], e = c + t.cca[p.a]; c < e; ++c)
        list.push(work_pair(c, p.b, true));
    }
    res.peak_list_size = std::max(res.peak_list_size, list.size());
  }
  res.untested.reserve(res.untested.size() + list.size());
  list.for_each([&](const WorkPair& p) { res.untested.push_back({p.a, p.b}); });
}

// Tests the allowed children of the split node against the other node of `p`
// and queues the overlapping pairs (SplitB: the children are b's), then, with
// the parent filter (Filter), sets the queued pairs' mask. No budget event may
// fall inside (see Budget::batch_ok). Without the filter this is the plain
// loop: every child tested, nothing more.
template <bool SplitB, bool Filter, class List>
inline void expand_batch(const Trees& t, const WorkPair& p, const Split& s, List& list,
                         CollisionResult& res) {
  const Sphere o = SplitB ? t.sa[p.a] : t.sb[p.b];
  const Sphere* kids = SplitB ? t.sb : t.sa;
  auto test = [&](int32_t c) {
    ++res.tests;
    const Sphere& k = kids[c];
    const double dx = o.x - k.x, dy = o.y - k.y, dz = o.z - k.z, rr = o.r + k.r;
    const bool ov = dx * dx + dy * dy + dz * dz <= rr * rr;
    const int32_t a = SplitB ? p.a : c, b = SplitB ? c : p.b;
    if (s.other_expandable || (SplitB ? t.expandable_b(c) : t.expandable_a(c)))
      list.push_if(work_pair(a, b, s.next_split_b), ov);
    else if (ov)
      settle(t, a, b, res);
  };
  if constexpr (!Filter) {
    for (int32_t c = s.first; c < s.end; ++c) test(c);
  } else {
    const std::size_t before = list.size();
    const int32_t n = s.end - s.first;
    if (n <= 64) {
      // Only the allowed children, by their bits: no branch per ruled-out child.
      for (uint64_t todo = allowed_children(p.allowed, n); todo != 0; todo &= todo - 1)
        test(s.first + std::countr_zero(todo));
    } else {
      for (int32_t c = s.first; c < s.end; ++c)
        if (is_allowed(p.allowed, c - s.first)) test(c);
    }
    const std::size_t queued = list.size() - before;
    if (queued >= kMaskFromPairs && s.filter_tests(t) > 0) {
      const uint32_t mask = FilterTests(t, s, p).mask(res);
      list.for_last(queued, [mask](WorkPair& w) { w.allowed = mask; });
    }
  }
}

// expand_batch without the parent filter, as tight as the work allows (the
// hot loop of a full traversal): the tests counted at once, pairs written
// branch-free straight into the list's storage, the branch on whether the
// other node is split further hoisted out of the loop; Uncapped (no depth cap
// inside the trees): a node is expandable iff it has children, so a pair of
// two unexpandable nodes is a leaf pair. Same tests, same order, same pairs.
template <bool SplitB, bool Uncapped, class List>
inline void expand_plain(const Trees& t, const WorkPair& p, const Split& s, List& list,
                         CollisionResult& res) {
  const Sphere o = SplitB ? t.sa[p.a] : t.sb[p.b];
  const Sphere* kids = SplitB ? t.sb : t.sa;
  const int32_t* kid_count = SplitB ? t.ccb : t.cca;
  res.tests += s.end - s.first;
  WorkPair* buf = list.raw();
  const std::size_t mask = list.mask(), start = list.tail();
  std::size_t tail = start;
  const int32_t next = s.next_split_b ? 1 : 0;
  auto overlaps = [&](int32_t c) {
    const Sphere& k = kids[c];
    const double dx = o.x - k.x, dy = o.y - k.y, dz = o.z - k.z, rr = o.r + k.r;
    return dx * dx + dy * dy + dz * dz <= rr * rr;
  };
  auto pair = [&](int32_t c) {
    return SplitB ? WorkPair{p.a, c, next, kAllChildren} : WorkPair{c, p.b, next, kAllChildren};
  };
  if (s.other_expandable) {
    for (int32_t c = s.first; c < s.end; ++c) {
      buf[tail & mask] = pair(c);
      tail += overlaps(c);
    }
  } else {
    for (int32_t c = s.first; c < s.end; ++c) {
      const bool ov = overlaps(c);
      const bool expandable =
          Uncapped ? kid_count[c] > 0 : (SplitB ? t.expandable_b(c) : t.expandable_a(c));
      if (expandable) {
        buf[tail & mask] = pair(c);
        tail += ov;
      } else if (ov) {
        const WorkPair w = pair(c);
        if constexpr (Uncapped)
          res.colliding.push_back({w.a, w.b});
        else
          settle(t, w.a, w.b, res);
      }
    }
  }
  list.commit(tail - start);
}

// The fast path's hot loop for the default query (FIFO, no parent filter, no
// front, no depth cap inside the trees): run_fast's batches with the queue's
// head and size, the test count and the peak in registers. Returns when the
// queue is empty or when the next pair's batch would reach a budget event
// (that pair is then back at the queue's head, for the general loop). Same
// tests, same order, same pairs as expand_plain.
void run_plain_fifo(const Trees& t, PairQueue& q, const Budget& budget, CollisionResult& res) {
  WorkPair* buf = q.raw();
  std::size_t mask = q.mask(), head = q.head(), size = q.size(), cap = q.capacity();
  int64_t tests = res.tests;
  std::size_t peak = res.peak_list_size;
  // Everything the loop reads, in locals (nothing inside changes it).
  const Sphere *const sa = t.sa, *const sb = t.sb;
  const int32_t *const fca = t.fca, *const cca = t.cca, *const fcb = t.fcb, *const ccb = t.ccb;
  std::vector<NodePair>& colliding = res.colliding;
  const int64_t next_event = budget.next_event();
  while (size > 0) {
    const WorkPair p = buf[head];
    const int32_t ca = cca[p.a], cb = ccb[p.b];
    const bool split_b = p.split_b ? cb > 0 : ca == 0 && cb > 0;
    const int32_t count = split_b ? cb : ca;
    if (tests + count > next_event) break;  // Budget::batch_ok
    head = (head + 1) & mask;
    --size;
    if (size + static_cast<std::size_t>(count) > cap) {
      q.set_state(head, size);
      q.ensure(static_cast<std::size_t>(count));
      buf = q.raw();
      mask = q.mask();
      head = q.head();
      cap = q.capacity();
    }
    tests += count;
    const Sphere o = split_b ? sa[p.a] : sb[p.b];
    const bool other_expandable = (split_b ? ca : cb) > 0;
    const int32_t first = split_b ? fcb[p.b] : fca[p.a], end = first + count;
    const Sphere* kids = split_b ? sb : sa;
    const int32_t* kid_count = split_b ? ccb : cca;
    const int32_t next = split_b ? 0 : 1;
    // Pair of child c: (p.a, c) when b is split, else (c, p.b).
    const int32_t keep = split_b ? p.a : p.b;
    std::size_t tail = head + size;
    auto overlaps = [&](int32_t c) {
      const Sphere& k = kids[c];
      const double dx = o.x - k.x, dy = o.y - k.y, dz = o.z - k.z, rr = o.r + k.r;
      return dx * dx + dy * dy + dz * dz <= rr * rr;
    };
    auto pair = [&](int32_t c) {
      return split_b ? WorkPair{keep, c, next, kAllChildren} : WorkPair{c, keep, next, kAllChildren};
    };
    if (other_expandable) {
      for (int32_t c = first; c < end; ++c) {
        buf[tail & mask] = pair(c);
        tail += overlaps(c);
      }
    } else {
      for (int32_t c = first; c < end; ++c) {
        const bool ov = overlaps(c);
        if (kid_count[c] > 0) {
          buf[tail & mask] = pair(c);
          tail += ov;
        } else if (ov) {
          colliding.push_back(split_b ? NodePair{keep, c} : NodePair{c, keep});
        }
      }
    }
    size = tail - head;
    peak = std::max(peak, size);
  }
  q.set_state(head, size);
  res.tests = tests;
  res.peak_list_size = peak;
}

// Fast path: children are tested as they are generated; the list holds only
// overlapping pairs that still need splitting.
template <bool Filter, class List>
void run_fast(const Trees& t, List& list, Budget& budget, bool record_front, CollisionResult& res) {
  bool stopped = false;
  while (!list.empty() && !stopped) {
    if constexpr (!Filter && std::is_same_v<List, PairQueue>) {
      if (!record_front && t.uncapped) {
        run_plain_fifo(t, list, budget, res);
        if (list.empty()) break;
      }
    }
    const WorkPair p = list.pop();
    const Split s(t, p);
    const int64_t most = (s.end - s.first) + (Filter ? s.filter_tests(t) : 0);
    if (!record_front && budget.batch_ok(res.tests, most)) {
      // Batch: no budget event inside; children tested against the fixed
      // sphere with branch-free pushes of the overlapping ones.
      list.ensure(static_cast<std::size_t>(s.end - s.first));
      if constexpr (!Filter) {
        if (t.uncapped) {
          if (s.split_b)
            expand_plain<true, true>(t, p, s, list, res);
          else
            expand_plain<false, true>(t, p, s, list, res);
        } else {
          if (s.split_b)
            expand_plain<true, false>(t, p, s, list, res);
          else
            expand_plain<false, false>(t, p, s, list, res);
        }
      } else if (s.split_b) {
        expand_batch<true, Filter>(t, p, s, list, res);
      } else {
        expand_batch<false, Filter>(t, p, s, list, res);
      }
      res.peak_list_size = std::max(res.peak_list_size, list.size());
      continue;
    }
    stopped = !test_children_one_by_one(
        t, p, s, budget, record_front, res, [&] { return list.size(); },
        [&](const WorkPair& w) { list.push(w); });
    res.peak_list_size = std::max(res.peak_list_size, list.size());
  }
  res.untested.reserve(res.untested.size() + list.size());
  list.for_each([&](const WorkPair& p) { res.untested.push_back({p.a, p.b}); });
}

// Best-first by deepest overlap with a capped heap.
struct HeapItem {
  double key;
  WorkPair p;
  bool operator<(const HeapItem& o) const { return key < o.key; }
};

inline double priority_of(PriorityKey key, const Sphere& p, const Sphere& q) {
  return key == PriorityKey::LargestSphere ? std::max(p.r, q.r) : penetration(p, q);
}

void run_priority(const Trees& t, std::vector<HeapItem>& heap, std::size_t cap, PriorityKey key,
                  Budget& budget, bool record_front, CollisionResult& res) {
  bool stopped = false;
  auto push = [&](const WorkPair& w) {
    heap.push_back({priority_of(key, t.sa[w.a], t.sb[w.b]), w});
    std::push_heap(heap.begin(), heap.end());
  };
  while (!heap.empty() && !stopped) {
    std::pop_heap(heap.begin(), heap.end());
    const WorkPair p = heap.back().p;
    heap.pop_back();
    const bool split_b = choose_split_b(t, p);
    const int32_t first = split_b ? t.fcb[p.b] : t.fca[p.a];
    const int32_t count = split_b ? t.ccb[p.b] : t.cca[p.a];
    if (heap.size() + static_cast<std::size_t>(count) > cap) {
      // Full: give up the lower-priority half (reported unrefined), keep the rest.
      std::sort(heap.begin(), heap.end());
      const std::size_t drop = std::max(heap.size() / 2, heap.size() + count - cap);
      for (std::size_t k = 0; k < drop && k < heap.size(); ++k)
        res.untested.push_back({heap[k].p.a, heap[k].p.b});
      heap.erase(heap.begin(), heap.begin() + std::min(drop, heap.size()));
      std::make_heap(heap.begin(), heap.end());
    }
    if (t.parent_filter) {
      const Split s(t, p);
      if (!record_front && count <= 64 && budget.batch_ok(res.tests, count + s.filter_tests(t))) {
        // Batch (no budget event inside), as expand_batch: the allowed
        // children by their bits, the pairs held until the mask is known.
        uint64_t held = 0;
        int num_held = 0;
        for (uint64_t todo = allowed_children(p.allowed, count); todo != 0; todo &= todo - 1) {
          const int32_t k = std::countr_zero(todo), c = first + k;
          const int32_t a = split_b ? p.a : c, b = split_b ? c : p.b;
          ++res.tests;
          if (!t.overlaps(a, b)) continue;
          if (t.expandable_a(a) || t.expandable_b(b)) {
            held |= uint64_t{1} << k;
            ++num_held;
          } else {
            settle(t, a, b, res);
          }
        }
        const uint32_t mask =
            static_cast<std::size_t>(num_held) >= kMaskFromPairs && s.filter_tests(t) > 0
                ? FilterTests(t, s, p).mask(res)
                : kAllChildren;
        for (; held != 0; held &= held - 1) {
          const int32_t c = first + std::countr_zero(held);
          push(work_pair(split_b ? p.a : c, split_b ? c : p.b, !split_b, mask));
        }
      } else {
        stopped = !test_children_one_by_one(
            t, p, s, budget, record_front, res, [&] { return heap.size(); }, push);
      }
    } else {
      // The plain loop (measured: the general one costs up to 2x here).
      StopReason reason = StopReason::Completed;
      for (int32_t c = first; c < first + count; ++c) {
        const int32_t a = split_b ? p.a : c, b = split_b ? c : p.b;
        if (!budget.allow(res.tests, heap.size(), reason)) {
          for (int32_t r = c; r < first + count; ++r)
            res.untested.push_back(split_b ? NodePair{p.a, r} : NodePair{r, p.b});
          res.interrupted = true;
          res.stop_reason = reason;
          stopped = true;
          break;
        }
        ++res.tests;
        if (!t.overlaps(a, b)) {
          if (record_front) res.front.push_back({a, b});
        } else if (t.expandable_a(a) || t.expandable_b(b)) {
          push(work_pair(a, b, !split_b));
        } else {
          settle(t, a, b, res);
        }
      }
    }
    res.peak_list_size = std::max(res.peak_list_size, heap.size());
  }
  res.untested.reserve(res.untested.size() + heap.size());
  for (const HeapItem& h : heap) res.untested.push_back({h.p.a, h.p.b});
}

thread_local PairQueue t_queue;
thread_local PairStack t_stack;
thread_local std::vector<HeapItem> t_heap;
thread_local std::vector<WorkPair> t_seeds;

}  // namespace

CollisionRequest CollisionRequest::paper_reference(double budget_seconds) {
  CollisionRequest r;
  r.budget_seconds = budget_seconds;
  r.mode = TraversalMode::BreadthFirstLiteral;
  r.clock_check_interval = 1;
  return r;
}

void validate(const CollisionRequest& request) {
  if (!(request.budget_seconds > 0.0))
    throw ParameterError("CollisionRequest::budget_seconds must be > 0 (infinity for none)");
  if (request.budget_tests < -1)
    throw ParameterError("CollisionRequest::budget_tests must be >= 0, or -1 for none");
  if (request.clock_check_interval < 1)
    throw ParameterError("CollisionRequest::clock_check_interval must be >= 1");
  if (request.depth_cap < 0) throw ParameterError("CollisionRequest::depth_cap must be >= 0");
  if (request.mode == TraversalMode::Priority && request.max_list_size < 8)
    throw ParameterError("CollisionRequest::max_list_size must be >= 8");
}

void collide(const SphereTree& a, const SphereTree& b, const CollisionRequest& request,
             CollisionResult& res) {
  if (std::isfinite(request.budget_seconds)) {  // one-time calibrations, outside the budget
    if (t_finish_cost == 0.0) t_finish_cost = output_seconds_per_pair();
    if (request.clock == ClockSource::CycleCounter) cycle_counter_hz();
  }
  const Clock::time_point start = Clock::now();
  validate(request);
  if (a.num_nodes() == 0 || b.num_nodes() == 0) throw ParameterError("collide: empty sphere tree");
  res.colliding.clear();
  res.untested.clear();
  res.front.clear();
  res.interrupted = false;
  res.stop_reason = StopReason::Completed;
  res.tests = 0;
  res.peak_list_size = 0;

  const bool literal = is_literal(request.mode);
  const Trees t{a.spheres.data(),     b.spheres.data(),
                a.first_child.data(), a.child_count.data(),
                b.first_child.data(), b.child_count.data(),
                a.level.data(),       b.level.data(),
                request.depth_cap,    request.parent_filter && !literal,
                request.depth_cap >= std::max(a.num_levels(), b.num_levels())};
  // Seeds: the root pair (Fig. 7: p.1 = root of a, p.2 = root of b, split p.2
  // first), or the previous front, splitting the shallower node first.
  std::vector<WorkPair>& seeds = t_seeds;
  seeds.clear();
  if (request.start_front) {
    seeds.reserve(request.start_front->size());
    for (const NodePair& p : *request.start_front) {
      if (p.a < 0 || p.a >= a.num_nodes() || p.b < 0 || p.b >= b.num_nodes())
        throw ParameterError("collide: start_front pair (" + std::to_string(p.a) + ", " +
                             std::to_string(p.b) + ") out of range");
      seeds.push_back(work_pair(p.a, p.b, a.level[p.a] >= b.level[p.b]));
    }
  } else {
    seeds.push_back(work_pair(0, 0, true));
  }
  Budget budget(request, start);
  StopReason reason = StopReason::Completed;
  std::size_t seeded = 0;
  auto seed_into = [&](auto&& push) {
    // Fast and priority modes test the seeds themselves before queueing them.
    for (; seeded < seeds.size(); ++seeded) {
      const WorkPair& s = seeds[seeded];
      if (!budget.allow(res.tests, seeds.size() - seeded, reason)) {
        res.interrupted = true;
        res.stop_reason = reason;
        for (std::size_t k = seeded; k < seeds.size(); ++k)
          res.untested.push_back({seeds[k].a, seeds[k].b});
        return false;
      }
      ++res.tests;
      if (!t.overlaps(s.a, s.b)) {
        if (request.record_front) res.front.push_back({s.a, s.b});
      } else if (t.expandable_a(s.a) || t.expandable_b(s.b)) {
        push(s);
      } else {
        settle(t, s.a, s.b, res);
      }
    }
    return true;
  };

  if (request.mode == TraversalMode::Priority) {
    t_heap.clear();
    const auto push = [&](const WorkPair& s) {
      t_heap.push_back({priority_of(request.priority, t.sa[s.a], t.sb[s.b]), s});
      std::push_heap(t_heap.begin(), t_heap.end());
    };
    if (seed_into(push))
      run_priority(t, t_heap, request.max_list_size, request.priority, budget, request.record_front,
                   res);
    else
      for (const HeapItem& h : t_heap) res.untested.push_back({h.p.a, h.p.b});
  } else {
    auto go = [&](auto& list) {
      list.clear();
      if (literal) {
        for (const WorkPair& s : seeds) list.push(s);
        run_literal(t, list, budget, request.record_front, res);
      } else if (seed_into([&](const WorkPair& s) { list.push(s); })) {
        if (t.parent_filter)
          run_fast<true>(t, list, budget, request.record_front, res);
        else
          run_fast<false>(t, list, budget, request.record_front, res);
      } else {
        list.for_each([&](const WorkPair& p) { res.untested.push_back({p.a, p.b}); });
      }
    };
    if (request.mode == TraversalMode::BreadthFirstFifo ||
        request.mode == TraversalMode::BreadthFirstLiteral)
      go(t_queue);
    else
      go(t_stack);
  }

  // Tightness reached: the shallowest inner node among the untested pairs.
  int level = std::max(a.num_levels(), b.num_levels()) - 1;
  for (const NodePair& p : res.untested) {
    if (t.cca[p.a] > 0) level = std::min(level, static_cast<int>(a.level[p.a]));
    if (t.ccb[p.b] > 0) level = std::min(level, static_cast<int>(b.level[p.b]));
  }
  res.completed_level = level;
  if (request.record_front) {
    // Unfinished work first, so that a budget-limited next frame refines it
    // before re-checking pruned pairs.
    const std::size_t pruned = res.front.size();
    res.front.insert(res.front.end(), res.untested.begin(), res.untested.end());
    res.front.insert(res.front.end(), res.colliding.begin(), res.colliding.end());
    std::rotate(res.front.begin(), res.front.begin() + pruned, res.front.end());
  }
  const Clock::time_point end = Clock::now();
  res.seconds = std::chrono::duration<double>(end - start).count();
  if (res.stop_reason == StopReason::TimeBudget && res.untested.size() >= 256) {
    const double observed =
        std::chrono::duration<double>(end - budget.m_stopped_at).count() / res.untested.size();
    // Smoothed and clipped, so that one preempted finish does not make later
    // queries stop far too early; never below the calibrated copy cost.
    t_finish_cost = std::max(output_seconds_per_pair(),
                             0.9 * t_finish_cost + 0.1 * std::min(observed, 4.0 * t_finish_cost));
  }
}

CollisionResult collide(const SphereTree& a, const SphereTree& b, const CollisionRequest& request) {
  CollisionResult r;
  collide(a, b, request, r);
  return r;
}

double finish_cost_per_pair() { return t_finish_cost; }

double calibrated_finish_cost_per_pair() { return output_seconds_per_pair(); }

}  // namespace icd::collision
