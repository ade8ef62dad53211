// The lock-free structures under two real threads (run these under TSan too).
#include <atomic>
#include <thread>

#include <gtest/gtest.h>

#include "cncd/drivers/seqlock.hpp"
#include "cncd/motion/spsc_ring.hpp"

namespace cncd::motion {
namespace {

// Two words a slot, so a torn copy would show as a mismatch.
struct Item {
  std::uint64_t value;
  std::uint64_t complement;
};

TEST(SpscRing, DeliversEverythingInOrderAcrossThreads) {
  SpscRing<Item, 64> ring;
  constexpr std::uint64_t kCount = 200'000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kCount;) {
      if (ring.push(Item{i, ~i})) {
        ++i;
      } else {
        std::this_thread::yield();
      }
    }
  });
  std::uint64_t expected = 0;
  while (expected < kCount) {
    Item item;
    if (!ring.pop(item)) {
      std::this_thread::yield();
      continue;
    }
    ASSERT_EQ(item.value, expected);
    ASSERT_EQ(item.complement, ~expected);
    ++expected;
  }
  producer.join();
  EXPECT_EQ(ring.size(), 0u);
}

TEST(SpscRing, ReportsFullAndEmpty) {
  SpscRing<int, 4> ring;
  int out = 0;
  EXPECT_FALSE(ring.pop(out));
  for (int i = 0; i < 4; ++i)
    EXPECT_TRUE(ring.push(i));
  EXPECT_FALSE(ring.push(9));
  ASSERT_NE(ring.front(), nullptr);
  EXPECT_EQ(*ring.front(), 0);
  EXPECT_TRUE(ring.pop(out));
  EXPECT_EQ(out, 0);
  EXPECT_TRUE(ring.push(4));
}

struct Snapshot {
  std::uint64_t values[24];
};

using drivers::Seqlock;

bool consistent(const Snapshot& s) {
  for (const auto v : s.values) {
    if (v != s.values[0]) return false;
  }
  return true;
}

// The writer keeps storing until the reader has made its reads, so that reads overlap writes
// for the whole run; without the sequence's re-check after the copy, a few thousand of these
// reads come back torn.
TEST(Seqlock, ReadersNeverSeeATornSnapshot) {
  Seqlock<Snapshot> lock;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    Snapshot s{};
    for (std::uint64_t n = 1; !done.load(std::memory_order_relaxed); ++n) {
      for (auto& v : s.values)
        v = n;
      lock.store(s);
    }
  });
  constexpr int kReads = 200'000;
  std::uint64_t last = 0;
  int torn = 0;
  int skipped = 0;  // try_load calls that overlapped a write
  for (int i = 0; i < kReads; ++i) {
    const Snapshot s = lock.load();
    torn += !consistent(s);
    EXPECT_GE(s.values[0], last);  // never goes back in time
    last = s.values[0];
    Snapshot t{};
    if (lock.try_load(t)) {
      torn += !consistent(t);
    } else {
      ++skipped;
    }
  }
  done = true;
  writer.join();
  EXPECT_EQ(torn, 0) << "of " << 2 * kReads - skipped << " reads";
  const std::uint64_t stored = lock.version();
  EXPECT_EQ(lock.load().values[0], stored);
}

}  // namespace
}  // namespace cncd::motion
