#include "cncd/web/admin_cli.hpp"

#include <termios.h>
#include <unistd.h>

#include <iomanip>
#include <istream>
#include <optional>
#include <ostream>

namespace cncd::web {
namespace {

struct Context {
  std::istream& in;
  std::ostream& out;
  std::ostream& err;
  const AdminOptions& options;
  std::string file;
};

// Echo off on a terminal while it lives; typed-ahead input is dropped first, as getpass does.
class Silence {
 public:
  explicit Silence(int fd) : fd_(fd) {
    if (::tcgetattr(fd_, &saved_) != 0) {
      fd_ = -1;
      return;
    }
    termios silent = saved_;
    silent.c_lflag &= ~static_cast<tcflag_t>(ECHO);
    silent.c_lflag |= ECHONL;  // the Enter key still shows
    ::tcsetattr(fd_, TCSAFLUSH, &silent);
  }
  ~Silence() {
    if (fd_ >= 0) ::tcsetattr(fd_, TCSANOW, &saved_);
  }
  Silence(const Silence&) = delete;
  Silence& operator=(const Silence&) = delete;

 private:
  int fd_;
  termios saved_{};
};

std::optional<std::string> read_line(std::istream& in) {
  std::string line;
  if (!std::getline(in, line)) return std::nullopt;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return line;
}

// The new password: asked twice on a terminal, else one line of standard input.
std::optional<std::string> new_password(Context& c, const std::string& user) {
  const int fd = c.options.input_fd;
  if (fd >= 0 && ::isatty(fd) == 1) {
    std::optional<std::string> first;
    std::optional<std::string> second;
    {
      Silence silence(fd);
      c.err << "New password for " << user << ": " << std::flush;
      first = read_line(c.in);
      c.err << "Again: " << std::flush;
      if (first) second = read_line(c.in);
    }
    if (!first || !second) {
      c.err << "cncd-web: no password given\n";
      return std::nullopt;
    }
    if (*first != *second) {
      c.err << "cncd-web: the two passwords differ; nothing changed\n";
      return std::nullopt;
    }
    return first;
  }
  auto line = read_line(c.in);
  if (!line) c.err << "cncd-web: no password on standard input (one line expected)\n";
  return line;
}

int usage(Context& c, const std::string& what) {
  c.err << "cncd-web: " << what << "\n" << admin_usage();
  return 2;
}

int failed(Context& c, const std::string& what) {
  c.err << "cncd-web: " << c.file << ": " << what << "\n";
  return 1;
}

int save(Context& c, UsersFile& users, const std::string& done) {
  if (auto error = users.save(); !error.empty()) {
    c.err << "cncd-web: " << error << "\n";
    return 1;
  }
  c.err << done << "\n";
  return 0;
}

int user_add(Context& c, UsersFile& users, const std::vector<std::string>& a) {
  // user add NAME --role ROLE (or --role=ROLE)
  std::optional<std::string> role_text;
  std::vector<std::string> rest;
  for (std::size_t i = 2; i < a.size(); ++i) {
    if (a[i] == "--role" && i + 1 < a.size()) {
      role_text = a[++i];
    } else if (a[i].starts_with("--role=")) {
      role_text = a[i].substr(7);
    } else {
      rest.push_back(a[i]);
    }
  }
  if (rest.size() != 1 || !role_text) return usage(c, "user add needs NAME and --role ROLE");
  const auto role = parse_role(*role_text);
  if (!role) return usage(c, "'" + *role_text + "' is not a role (" + role_names() + ")");
  const std::string& name = rest[0];
  if (auto why = check_user_name(name); !why.empty()) return failed(c, "'" + name + "': " + why);
  if (users.find(name) != nullptr) return failed(c, "user '" + name + "' exists already");
  const auto password = new_password(c, name);
  if (!password) return 1;
  if (auto why = users.add(name, *role, *password); !why.empty()) return failed(c, why);
  return save(c, users,
              "added user " + name + " (" + std::string(role_name(*role)) + ") to " + c.file);
}

int user_list(Context& c, const UsersFile& users) {
  if (users.users().empty()) c.err << c.file << ": no users\n";
  for (const auto& u : users.users()) {
    c.out << std::left << std::setw(33) << u.name << std::setw(9) << role_name(u.role)
          << (u.password_hash == "-" ? "no-password" : "password   ") << " keys:";
    for (const auto& k : u.keys)
      c.out << ' ' << k.id;
    c.out << '\n';
  }
  return 0;
}

int run(Context& c, UsersFile& users, const std::vector<std::string>& a) {
  const std::string command = a[0] + (a.size() > 1 ? " " + a[1] : "");
  const auto arity = [&](std::size_t n) { return a.size() == n; };
  if (command == "user add") return user_add(c, users, a);
  if (command == "user list") {
    if (!arity(2)) return usage(c, "user list takes no arguments");
    return user_list(c, users);
  }
  if (command == "user del") {
    if (!arity(3)) return usage(c, "user del needs NAME");
    if (auto why = users.remove(a[2]); !why.empty()) return failed(c, why);
    return save(c, users, "deleted user " + a[2] + " from " + c.file);
  }
  if (command == "user passwd") {
    if (!arity(3)) return usage(c, "user passwd needs NAME");
    if (users.find(a[2]) == nullptr) return failed(c, "no user '" + a[2] + "'");
    const auto password = new_password(c, a[2]);
    if (!password) return 1;
    if (auto why = users.set_password(a[2], *password); !why.empty()) return failed(c, why);
    return save(c, users, "changed the password of " + a[2] + " in " + c.file);
  }
  if (command == "key add") {
    if (!arity(3)) return usage(c, "key add needs NAME");
    std::string why;
    const auto key = users.add_key(a[2], why);
    if (!key) return failed(c, why);
    if (const int rc = save(
            c, users, "key " + key->id + " added for " + a[2] + "; it is shown only this once:");
        rc != 0) {
      return rc;
    }
    c.out << key->key << '\n';
    return 0;
  }
  if (command == "key del") {
    if (!arity(4)) return usage(c, "key del needs NAME and KEYID");
    if (auto why = users.remove_key(a[2], a[3]); !why.empty()) return failed(c, why);
    return save(c, users, "deleted key " + a[3] + " of " + a[2] + " from " + c.file);
  }
  return usage(c, "unknown command '" + command + "'");
}

}  // namespace

bool is_admin_command(const std::vector<std::string>& args) {
  return !args.empty() && (args[0] == "user" || args[0] == "key");
}

std::string admin_usage() {
  return "usage: cncd-web --ini INI user add NAME --role " + role_names() +
         "\n"
         "       cncd-web --ini INI user del NAME\n"
         "       cncd-web --ini INI user passwd NAME\n"
         "       cncd-web --ini INI user list\n"
         "       cncd-web --ini INI key add NAME\n"
         "       cncd-web --ini INI key del NAME KEYID\n"
         "A password is read from standard input (one line), or asked for twice on a "
         "terminal.\n";
}

int run_admin_command(const std::vector<std::string>& args, const config::WebConfig& web,
                      std::istream& in, std::ostream& out, std::ostream& err,
                      const AdminOptions& options) {
  Context c{in, out, err, options, web.users_file.string()};
  if (!is_admin_command(args) || args.size() < 2) return usage(c, "expected a user or key command");
  if (web.users_file.empty()) {
    err << "cncd-web: no users file: set [WEB] USERS_FILE or a state directory\n";
    return 1;
  }
  UsersFile users(web.users_file, options.cost);
  if (auto error = users.load(); !error.empty()) {
    err << "cncd-web: " << error << "\n";
    return 1;
  }
  try {
    return run(c, users, args);
  } catch (const std::exception& e) {
    err << "cncd-web: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace cncd::web
