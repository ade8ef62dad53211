// `cncd-web --ini INI user ...` and `key ...`: managing the users file from a shell.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/web/users.hpp"

namespace cncd::web {

struct AdminOptions {
  PasswordCost cost;  // for new password hashes
  // The descriptor `in` reads from. When it is a terminal, passwords are prompted for on
  // `err` twice with echo off (termios); otherwise one line is read from `in`. -1: `in` is
  // not a terminal.
  int input_fd = -1;
};

// True when `args` (the command line after the options, e.g. {"user", "add", "alice", ...})
// is an admin command rather than the server's own arguments.
bool is_admin_command(const std::vector<std::string>& args);

// Runs one admin command on web.users_file:
//   user add NAME --role ROLE   password from `in` (one line) or prompted twice on a terminal
//   user del NAME
//   user passwd NAME            new password as for add
//   user list                   name, role, whether a password is set, key ids
//   key add NAME                prints the new key once on `out`
//   key del NAME KEYID
// Results go to `out`, errors (naming the file, the user or the argument) to `err`.
// Returns 0 on success, 2 for a usage error (with the usage on `err`), 1 for any other error.
int run_admin_command(const std::vector<std::string>& args, const config::WebConfig& web,
                      std::istream& in, std::ostream& out, std::ostream& err,
                      const AdminOptions& options = {});

// The usage text of the admin commands.
std::string admin_usage();

}  // namespace cncd::web
