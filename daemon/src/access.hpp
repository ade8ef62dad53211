// Who may do what on the control socket, decided from the peer's credentials (SO_PEERCRED,
// SO_PEERGROUPS) as the D-Bus system bus does: everyone may connect, the credentials decide.
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>

#include "rpc.hpp"

namespace cncd::daemon {

struct AccessPolicy {
  uid_t owner = 0;                     // the daemon's own user: full control, like root
  std::optional<gid_t> read_group;     // [CNCD] READ_GROUP
  std::optional<gid_t> control_group;  // [CNCD] CONTROL_GROUP
};

// Resolves group names to ids. Returns "" or an error naming the unknown group.
std::string make_access_policy(const std::string& read_group, const std::string& control_group,
                               AccessPolicy& policy);

// The access of the peer on a connected socket; `who` describes the peer for messages, and
// `uid`, when given, receives its user id.
Access peer_access(int fd, const AccessPolicy& policy, std::string& who, uid_t* uid = nullptr);

}  // namespace cncd::daemon
