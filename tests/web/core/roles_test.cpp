// The role table: what each role may call and what needs the control lease.
#include "cncd/web/roles.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace cncd::web {
namespace {

const std::vector<std::string> kObserver{
    "status.get",  "status.subscribe", "status.unsubscribe", "errors.list",  "system.info",
    "tool.list",   "offsets.get",      "jobs.history",       "jobs.stats",   "program.preview",
    "web.session", "lease.get",        "files.list",         "machine.estop"};
const std::vector<std::string> kOperator{
    "machine.reset", "machine.on",    "machine.off",    "machine.home",     "jog.start",
    "jog.stop",      "jog.increment", "jog.heartbeat",  "program.open",     "files.open",
    "program.run",   "program.step",  "program.pause",  "program.resume",   "program.abort",
    "mdi.execute",   "override.feed", "override.rapid", "override.spindle", "tool.change_done",
    "wait.done",     "lease.take",    "lease.release"};
const std::vector<std::string> kSetter{"tool.set", "offsets.set", "files.rename", "files.delete",
                                       "upload"};
const std::vector<std::string> kAdmin{"users.list", "users.add", "users.delete", "users.passwd"};

TEST(RolesTest, NamesRoundTrip) {
  for (const Role role : {Role::observer, Role::operator_, Role::setter, Role::admin}) {
    EXPECT_EQ(parse_role(role_name(role)), role);
  }
  EXPECT_EQ(role_name(Role::operator_), "operator");
  EXPECT_EQ(parse_role("Admin"), std::nullopt);
  EXPECT_EQ(parse_role(""), std::nullopt);
  EXPECT_EQ(role_names(), "observer|operator|setter|admin");
}

TEST(RolesTest, EachRoleGetsItsMethodsAndThoseOfTheRolesBefore) {
  const std::vector<std::vector<std::string>> lists{kObserver, kOperator, kSetter, kAdmin};
  for (int r = 0; r < 4; ++r) {
    const auto role = static_cast<Role>(r);
    for (int l = 0; l < 4; ++l) {
      for (const auto& method : lists[static_cast<std::size_t>(l)]) {
        EXPECT_EQ(allowed(role, method), l <= r) << role_name(role) << " " << method;
        EXPECT_EQ(required_role(method), static_cast<Role>(l)) << method;
      }
    }
    std::vector<std::string> expected;
    for (int l = 0; l <= r; ++l) {
      expected.insert(expected.end(), lists[static_cast<std::size_t>(l)].begin(),
                      lists[static_cast<std::size_t>(l)].end());
    }
    auto got = methods(role);
    std::sort(expected.begin(), expected.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected) << role_name(role);
  }
}

TEST(RolesTest, UnknownMethodsAreForNobody) {
  for (const std::string method :
       {"", "machine", "status.get ", "Status.get", "override.*", "debug.crash", "users"}) {
    EXPECT_FALSE(allowed(Role::admin, method)) << method;
    EXPECT_EQ(required_role(method), std::nullopt) << method;
    EXPECT_FALSE(needs_lease(method)) << method;
  }
  EXPECT_EQ(refusal_message("debug.crash", Role::admin),
            "method debug.crash is not available through cncd-web");
}

TEST(RolesTest, OnlyMotionNeedsTheLeaseAndStoppingNever) {
  std::vector<std::string> leased;
  for (const auto& method : methods(Role::admin)) {
    if (needs_lease(method)) leased.push_back(method);
  }
  EXPECT_EQ(leased, (std::vector<std::string>{"machine.home", "jog.start", "jog.increment",
                                              "program.run", "program.step", "mdi.execute"}));
  for (const std::string stop : {"machine.estop", "program.pause", "program.abort", "jog.stop",
                                 "program.resume", "machine.on", "override.feed"}) {
    EXPECT_FALSE(needs_lease(stop)) << stop;
  }
}

TEST(RolesTest, RefusalNamesMethodRoleAndCaller) {
  EXPECT_EQ(refusal_message("program.run", Role::observer),
            "method program.run needs role operator; you are observer");
  EXPECT_EQ(refusal_message("users.add", Role::setter),
            "method users.add needs role admin; you are setter");
}

}  // namespace
}  // namespace cncd::web
