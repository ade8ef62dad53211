#include "access.hpp"

#include <grp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <vector>

namespace cncd::daemon {
namespace {

std::string resolve(const std::string& name, std::optional<gid_t>& gid) {
  if (name.empty()) return "";
  std::vector<char> buffer(16384);
  group entry{};
  group* found = nullptr;
  if (getgrnam_r(name.c_str(), &entry, buffer.data(), buffer.size(), &found) != 0 ||
      found == nullptr) {
    return "group '" + name + "' does not exist";
  }
  gid = found->gr_gid;
  return "";
}

std::vector<gid_t> peer_groups(int fd) {
  std::vector<gid_t> groups(64);
  for (int attempt = 0; attempt < 4; ++attempt) {
    socklen_t len = static_cast<socklen_t>(groups.size() * sizeof(gid_t));
    if (getsockopt(fd, SOL_SOCKET, SO_PEERGROUPS, groups.data(), &len) == 0) {
      groups.resize(len / sizeof(gid_t));
      return groups;
    }
    if (errno != ERANGE) break;
    groups.resize(len / sizeof(gid_t) + 1);
  }
  return {};
}

}  // namespace

std::string make_access_policy(const std::string& read_group, const std::string& control_group,
                               AccessPolicy& policy) {
  policy.owner = geteuid();
  std::string error = resolve(read_group, policy.read_group);
  const std::string control_error = resolve(control_group, policy.control_group);
  if (!control_error.empty()) error += (error.empty() ? "" : "; ") + control_error;
  return error;
}

Access peer_access(int fd, const AccessPolicy& policy, std::string& who, uid_t* uid) {
  ucred cred{};
  socklen_t len = sizeof cred;
  if (getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &len) != 0) {
    who = "unknown peer";
    return Access::none;
  }
  who = "uid " + std::to_string(cred.uid) + " pid " + std::to_string(cred.pid);
  if (uid != nullptr) *uid = cred.uid;
  if (cred.uid == 0 || cred.uid == policy.owner) return Access::control;
  std::vector<gid_t> groups = peer_groups(fd);
  groups.push_back(cred.gid);
  auto member = [&](const std::optional<gid_t>& gid) {
    return gid && std::find(groups.begin(), groups.end(), *gid) != groups.end();
  };
  if (member(policy.control_group)) return Access::control;
  if (member(policy.read_group)) return Access::read;
  return Access::none;
}

}  // namespace cncd::daemon
