// The control lease: one session at a time, taken over only on purpose, changes observed.
#include "cncd/web/lease.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace cncd::web {
namespace {

Session session(const std::string& id, const std::string& user, const std::string& address) {
  Session s;
  s.id = id;
  s.user = user;
  s.address = address;
  return s;
}

struct Seen {
  std::optional<LeaseHolder> holder;
  std::uint64_t version;
};

TEST(ControlLeaseTest, TakenWhenFreeRefusedWhenHeldForcedOnPurpose) {
  TimePoint now = TimePoint(std::chrono::hours(1000));
  ControlLease lease([&] { return now; });
  std::vector<Seen> seen;
  lease.set_observer([&](const std::optional<LeaseHolder>& h, std::uint64_t v) {
    seen.push_back({h, v});
  });
  const Session alice = session("a1", "alice", "10.0.0.1");
  const Session bob = session("b1", "bob", "10.0.0.2");
  EXPECT_FALSE(lease.holder());
  EXPECT_EQ(lease.version(), 0u);

  auto r = lease.take(alice, false);
  EXPECT_TRUE(r.ok);
  ASSERT_TRUE(r.holder);
  EXPECT_EQ(r.holder->session, "a1");
  EXPECT_EQ(r.holder->user, "alice");
  EXPECT_EQ(r.holder->address, "10.0.0.1");
  EXPECT_EQ(r.holder->since, now);
  EXPECT_TRUE(lease.held_by("a1"));

  now += std::chrono::minutes(5);
  r = lease.take(alice, false);  // already hers: unchanged, no notification
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.holder->since, now - std::chrono::minutes(5));

  r = lease.take(bob, false);
  EXPECT_FALSE(r.ok);
  ASSERT_TRUE(r.holder);
  EXPECT_EQ(r.holder->user, "alice");  // who to ask
  EXPECT_TRUE(lease.held_by("a1"));
  EXPECT_FALSE(lease.release("b1"));  // not his to release

  r = lease.take(bob, true);
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.holder->user, "bob");
  EXPECT_FALSE(lease.held_by("a1"));
  EXPECT_FALSE(lease.release("a1"));

  lease.session_closed("b1");
  EXPECT_FALSE(lease.holder());
  EXPECT_EQ(lease.version(), 3u);

  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0].holder->user, "alice");
  EXPECT_EQ(seen[0].version, 1u);
  EXPECT_EQ(seen[1].holder->user, "bob");
  EXPECT_EQ(seen[1].version, 2u);
  EXPECT_FALSE(seen[2].holder);
  EXPECT_EQ(seen[2].version, 3u);
}

TEST(ControlLeaseTest, TheObserverMayCallBackIntoTheLease) {
  ControlLease lease;
  std::optional<LeaseHolder> read;
  lease.set_observer([&](const std::optional<LeaseHolder>&, std::uint64_t) {
    read = lease.holder();  // would deadlock if called under the lease's lock
  });
  lease.take(session("s", "u", "a"), false);
  ASSERT_TRUE(read);
  EXPECT_EQ(read->session, "s");
}

}  // namespace
}  // namespace cncd::web
