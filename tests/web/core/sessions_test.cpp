// Sessions behind the cookie and the login limiter, on a clock the test moves.
#include "cncd/web/sessions.hpp"

#include <gtest/gtest.h>

#include <set>

namespace cncd::web {
namespace {

using std::chrono::hours;
using std::chrono::seconds;

class FakeClock {
 public:
  Clock clock() {
    return [this] { return now_; };
  }
  void advance(std::chrono::system_clock::duration d) { now_ += d; }
  TimePoint now() const { return now_; }

 private:
  TimePoint now_ = TimePoint(hours(24 * 365 * 50));
};

bool is_hex(const std::string& text, std::size_t length) {
  return text.size() == length && text.find_first_not_of("0123456789abcdef") == std::string::npos;
}

TEST(SessionStoreTest, ASessionIsFoundByItsTokenUntilItExpires) {
  FakeClock clock;
  SessionStore store(hours(12), clock.clock());
  const Session s = store.create("alice", Role::operator_, "192.168.1.20");
  EXPECT_TRUE(is_hex(s.token, 64)) << s.token;
  EXPECT_TRUE(is_hex(s.id, 16)) << s.id;
  EXPECT_EQ(s.created, clock.now());
  EXPECT_EQ(s.expires, clock.now() + hours(12));
  auto found = store.find(s.token);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->user, "alice");
  EXPECT_EQ(found->role, Role::operator_);
  EXPECT_EQ(found->address, "192.168.1.20");
  EXPECT_EQ(found->id, s.id);
  EXPECT_EQ(store.find_id(s.id)->token, s.token);
  EXPECT_FALSE(store.find(s.id));           // the id is no token
  EXPECT_FALSE(store.find(s.token + "0"));  // nor is a longer one
  EXPECT_FALSE(store.find(""));
  clock.advance(hours(12) - seconds(1));
  EXPECT_TRUE(store.find(s.token));
  clock.advance(seconds(1));
  EXPECT_FALSE(store.find(s.token));
  EXPECT_EQ(store.size(), 0u);  // dropped when found expired
}

TEST(SessionStoreTest, TokensAndIdsAreDistinct) {
  SessionStore store(hours(1));
  std::set<std::string> tokens;
  std::set<std::string> ids;
  for (int i = 0; i < 1000; ++i) {
    const Session s = store.create("u", Role::observer, "a");
    tokens.insert(s.token);
    ids.insert(s.id);
  }
  EXPECT_EQ(tokens.size(), 1000u);
  EXPECT_EQ(ids.size(), 1000u);
}

TEST(SessionStoreTest, LogoutDropUserAndExpire) {
  FakeClock clock;
  SessionStore store(hours(1), clock.clock());
  const Session a1 = store.create("alice", Role::admin, "a");
  const Session a2 = store.create("alice", Role::admin, "b");
  const Session b = store.create("bob", Role::observer, "c");
  EXPECT_TRUE(store.drop(a1.token));
  EXPECT_FALSE(store.drop(a1.token));
  EXPECT_FALSE(store.find(a1.token));
  const Session a3 = store.create("alice", Role::admin, "d");
  const auto dropped = store.drop_user("alice");
  EXPECT_EQ(std::set<std::string>(dropped.begin(), dropped.end()),
            (std::set<std::string>{a2.id, a3.id}));
  EXPECT_FALSE(store.find(a2.token));
  EXPECT_TRUE(store.find(b.token));
  clock.advance(hours(1));
  const Session c = store.create("carol", Role::setter, "e");
  EXPECT_EQ(store.expire(), std::vector<std::string>{b.id});
  EXPECT_EQ(store.size(), 1u);
  EXPECT_TRUE(store.find(c.token));
}

TEST(LoginLimiterTest, FiveFailuresFromAnAddressRefuseItForTheRestOfTheMinute) {
  FakeClock clock;
  LoginLimiter limiter(clock.clock());
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(limiter.retry_after("10.0.0.1", "user" + std::to_string(i)), seconds(0)) << i;
    limiter.failed("10.0.0.1", "user" + std::to_string(i));
    clock.advance(seconds(2));
  }
  // The first failure was 10 s ago: 50 s to wait, whatever name is tried.
  EXPECT_EQ(limiter.retry_after("10.0.0.1", "someone"), seconds(50));
  EXPECT_EQ(limiter.retry_after("10.0.0.2", "someone"), seconds(0));  // another address
  clock.advance(seconds(49) + std::chrono::milliseconds(500));
  EXPECT_EQ(limiter.retry_after("10.0.0.1", "someone"), seconds(1));  // rounded up
  clock.advance(std::chrono::milliseconds(500));
  EXPECT_EQ(limiter.retry_after("10.0.0.1", "someone"), seconds(0));
}

TEST(LoginLimiterTest, FiveFailuresForANameRefuseItFromEveryAddress) {
  FakeClock clock;
  LoginLimiter limiter(clock.clock());
  for (int i = 0; i < 5; ++i)
    limiter.failed("10.0.0." + std::to_string(i), "alice");
  EXPECT_EQ(limiter.retry_after("10.9.9.9", "alice"), seconds(60));
  EXPECT_EQ(limiter.retry_after("10.9.9.9", "bob"), seconds(0));
  // A success (the server only gets one when not refused) forgets the name's failures only.
  limiter.succeeded("alice");
  EXPECT_EQ(limiter.retry_after("10.9.9.9", "alice"), seconds(0));
  for (int i = 0; i < 5; ++i)
    limiter.failed("10.0.0.7", "x" + std::to_string(i));
  limiter.succeeded("x0");
  EXPECT_EQ(limiter.retry_after("10.0.0.7", "x0"), seconds(60));
}

TEST(LoginLimiterTest, FourFailuresAreNotEnough) {
  FakeClock clock;
  LoginLimiter limiter(clock.clock());
  for (int i = 0; i < 4; ++i)
    limiter.failed("a", "u");
  EXPECT_EQ(limiter.retry_after("a", "u"), seconds(0));
  limiter.failed("a", "u");
  EXPECT_GT(limiter.retry_after("a", "u"), seconds(0));
}

TEST(LoginLimiterTest, MemoryStaysBoundedUnderAFloodOfNames) {
  FakeClock clock;
  LoginLimiter limiter(clock.clock(), 5, seconds(60), 100);
  // The attacker's own address stays refused while it floods names...
  for (int i = 0; i < 5; ++i)
    limiter.failed("attacker", "victim");
  for (int i = 0; i < 10000; ++i) {
    clock.advance(std::chrono::milliseconds(1));
    limiter.failed("attacker", "name" + std::to_string(i));
  }
  EXPECT_GT(limiter.retry_after("attacker", "new"), seconds(0));
  // ...while the oldest names are forgotten: "victim" among them.
  EXPECT_EQ(limiter.retry_after("elsewhere", "victim"), seconds(0));
}

}  // namespace
}  // namespace cncd::web
