#include "cncd/web/users.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <utility>

#include "crypto.hpp"

namespace cncd::web {
namespace {

constexpr std::string_view kKeyPrefix = "cncd_";

std::string errno_text() {
  return std::strerror(errno);
}

std::string mode_text(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

bool is_hex(std::string_view text, std::size_t length) {
  return text.size() == length &&
         text.find_first_not_of("0123456789abcdef") == std::string_view::npos;
}

std::vector<std::string_view> fields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t at = 0;
  while (true) {
    at = line.find_first_not_of(" \t", at);
    if (at == std::string_view::npos) break;
    const std::size_t end = std::min(line.find_first_of(" \t", at), line.size());
    out.push_back(line.substr(at, end - at));
    at = end;
  }
  return out;
}

// One line of the file, or why it is not one.
std::string parse_user(std::string_view line, User& user) {
  const auto f = fields(line);
  if (f.size() < 3) return "expected NAME ROLE PASSWORD_HASH [key:ID:SHA256]...";
  if (auto why = check_user_name(f[0]); !why.empty()) {
    return "'" + std::string(f[0]) + "': " + why;
  }
  const auto role = parse_role(f[1]);
  if (!role) return "'" + std::string(f[1]) + "' is not a role (" + role_names() + ")";
  if (f[2] != "-" && !f[2].starts_with("$argon2id$")) {
    return "the password hash is neither '-' nor an argon2id hash ($argon2id$...)";
  }
  user = User{std::string(f[0]), *role, std::string(f[2]), {}};
  for (std::size_t i = 3; i < f.size(); ++i) {
    const std::string_view k = f[i];
    if (!k.starts_with("key:") || k.size() != 4 + 8 + 1 + 64 || k[12] != ':' ||
        !is_hex(k.substr(4, 8), 8) || !is_hex(k.substr(13), 64)) {
      return "'" + std::string(k) + "' is not key:ID:SHA256 (8 and 64 lower-case hex digits)";
    }
    for (const auto& have : user.keys) {
      if (have.id == k.substr(4, 8)) return "key id " + have.id + " appears twice";
    }
    user.keys.push_back({std::string(k.substr(4, 8)), std::string(k.substr(13))});
  }
  return "";
}

}  // namespace

UsersFile::UsersFile(std::filesystem::path path, PasswordCost cost)
    : path_(std::move(path)), cost_(cost) {}

std::string UsersFile::load() {
  const std::string file = path_.string();
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) {
    if (errno == ENOENT) {
      users_.clear();
      stamp_ = {};
      return "";
    }
    return file + ": cannot open: " + errno_text();
  }
  struct stat st {};
  std::string text;
  std::string error;
  if (::fstat(fd, &st) != 0) {
    error = file + ": cannot stat: " + errno_text();
  } else if (!S_ISREG(st.st_mode)) {
    error = file + ": not a regular file";
  } else if ((st.st_mode & 077) != 0) {
    error = file + ": mode " + mode_text(st.st_mode) +
            " lets the group or others at the password hashes; chmod 600 " + file;
  } else {
    char buffer[8192];
    while (true) {
      const ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) error = file + ": cannot read: " + errno_text();
      if (n <= 0) break;
      text.append(buffer, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  if (!error.empty()) return error;

  std::vector<User> users;
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto f = fields(line);
    if (f.empty() || f[0].starts_with("#")) continue;
    User user;
    if (auto why = parse_user(line, user); !why.empty()) {
      return file + ":" + std::to_string(number) + ": " + why;
    }
    const auto same = [&](const User& u) { return u.name == user.name; };
    if (std::any_of(users.begin(), users.end(), same)) {
      return file + ":" + std::to_string(number) + ": user '" + user.name + "' appears twice";
    }
    users.push_back(std::move(user));
  }
  users_ = std::move(users);
  stamp_ = {true, st.st_dev, st.st_ino, st.st_size,
            st.st_mtim.tv_sec * 1'000'000'000LL + st.st_mtim.tv_nsec};
  return "";
}

bool UsersFile::changed_on_disk() const {
  struct stat st {};
  if (::stat(path_.c_str(), &st) != 0) return stamp_.exists;
  return !stamp_.exists || st.st_dev != stamp_.dev || st.st_ino != stamp_.ino ||
         st.st_size != stamp_.size ||
         st.st_mtim.tv_sec * 1'000'000'000LL + st.st_mtim.tv_nsec != stamp_.mtime_ns;
}

std::string UsersFile::save() {
  const std::string file = path_.string();
  const std::filesystem::path dir = path_.parent_path().empty() ? "." : path_.parent_path();
  std::error_code ec;
  if (!std::filesystem::exists(dir, ec)) {
    std::filesystem::create_directories(dir, ec);
    if (ec) return dir.string() + ": cannot create: " + ec.message();
    std::filesystem::permissions(dir, std::filesystem::perms::owner_all, ec);
  }
  std::string text =
      "# cncd-web users: NAME ROLE PASSWORD_HASH [key:ID:SHA256]...\n"
      "# Written by cncd-web; change it with `cncd-web --ini INI user ...` and `key ...`.\n";
  for (const auto& u : users_) {
    text += u.name + " " + std::string(role_name(u.role)) + " " + u.password_hash;
    for (const auto& k : u.keys)
      text += " key:" + k.id + ":" + k.sha256;
    text += '\n';
  }
  std::string temp = file + ".tmp-XXXXXX";
  const int fd = ::mkostemp(temp.data(), O_CLOEXEC);  // mode 0600
  if (fd < 0) return file + ": cannot create a temporary file beside it: " + errno_text();
  std::string error;
  std::size_t written = 0;
  while (written < text.size() && error.empty()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) error = file + ": cannot write: " + errno_text();
    if (n > 0) written += static_cast<std::size_t>(n);
  }
  if (error.empty() && ::fsync(fd) != 0) error = file + ": cannot fsync: " + errno_text();
  ::close(fd);
  if (error.empty() && ::rename(temp.c_str(), file.c_str()) != 0) {
    error = file + ": cannot replace: " + errno_text();
  }
  if (!error.empty()) {
    ::unlink(temp.c_str());
    return error;
  }
  if (const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dfd >= 0) {
    ::fsync(dfd);  // the rename itself reaches the disk
    ::close(dfd);
  }
  struct stat st {};
  if (::stat(file.c_str(), &st) == 0) {
    stamp_ = {true, st.st_dev, st.st_ino, st.st_size,
              st.st_mtim.tv_sec * 1'000'000'000LL + st.st_mtim.tv_nsec};
  }
  return "";
}

const User* UsersFile::find(std::string_view name) const {
  for (const auto& u : users_) {
    if (u.name == name) return &u;
  }
  return nullptr;
}

User* UsersFile::entry(std::string_view name) {
  for (auto& u : users_) {
    if (u.name == name) return &u;
  }
  return nullptr;
}

std::string UsersFile::add(std::string_view name, Role role, std::string_view password) {
  if (auto why = check_user_name(name); !why.empty()) return why;
  if (find(name) != nullptr) return "user '" + std::string(name) + "' exists already";
  if (auto why = web::check_password(password); !why.empty()) return why;
  users_.push_back(User{std::string(name), role, hash_password(password, cost_), {}});
  return "";
}

std::string UsersFile::add(std::string_view name, Role role, HashedPassword hash) {
  if (auto why = check_user_name(name); !why.empty()) return why;
  if (find(name) != nullptr) return "user '" + std::string(name) + "' exists already";
  users_.push_back(User{std::string(name), role, std::move(hash.encoded), {}});
  return "";
}

std::string UsersFile::set_password(std::string_view name, HashedPassword hash) {
  User* user = entry(name);
  if (user == nullptr) return "no user '" + std::string(name) + "'";
  user->password_hash = std::move(hash.encoded);
  return "";
}

std::string UsersFile::remove(std::string_view name) {
  const auto it =
      std::find_if(users_.begin(), users_.end(), [&](const User& u) { return u.name == name; });
  if (it == users_.end()) return "no user '" + std::string(name) + "'";
  users_.erase(it);
  return "";
}

std::string UsersFile::set_password(std::string_view name, std::string_view password) {
  User* user = entry(name);
  if (user == nullptr) return "no user '" + std::string(name) + "'";
  if (auto why = web::check_password(password); !why.empty()) return why;
  user->password_hash = hash_password(password, cost_);
  return "";
}

std::string UsersFile::set_role(std::string_view name, Role role) {
  User* user = entry(name);
  if (user == nullptr) return "no user '" + std::string(name) + "'";
  user->role = role;
  return "";
}

std::optional<NewApiKey> UsersFile::add_key(std::string_view name, std::string& error) {
  User* user = entry(name);
  if (user == nullptr) {
    error = "no user '" + std::string(name) + "'";
    return std::nullopt;
  }
  NewApiKey key;
  do {
    key.id = crypto::hex(crypto::random_bytes(4));
  } while (std::any_of(user->keys.begin(), user->keys.end(),
                       [&](const ApiKeyHash& k) { return k.id == key.id; }));
  key.key = std::string(kKeyPrefix) + crypto::base64url(crypto::random_bytes(32));
  user->keys.push_back({key.id, crypto::sha256_hex(key.key)});
  return key;
}

std::string UsersFile::remove_key(std::string_view name, std::string_view id) {
  User* user = entry(name);
  if (user == nullptr) return "no user '" + std::string(name) + "'";
  const auto it = std::find_if(user->keys.begin(), user->keys.end(),
                               [&](const ApiKeyHash& k) { return k.id == id; });
  if (it == user->keys.end()) {
    return "user '" + std::string(name) + "' has no key " + std::string(id);
  }
  user->keys.erase(it);
  return "";
}

const User* UsersFile::check_password(std::string_view name, std::string_view password) const {
  const User* user = find(name);
  if (user == nullptr || user->password_hash == "-") {
    // As slow as a real check, so that answers do not tell which names exist.
    if (dummy_hash_.empty()) dummy_hash_ = hash_password("cncd-web", cost_);
    verify_password(dummy_hash_, password);
    return nullptr;
  }
  return verify_password(user->password_hash, password) ? user : nullptr;
}

const User* UsersFile::check_key(std::string_view key) const {
  if (!key.starts_with(kKeyPrefix)) return nullptr;
  const std::string digest = crypto::sha256_hex(key);
  const User* found = nullptr;
  for (const auto& u : users_) {
    for (const auto& k : u.keys) {
      if (crypto::equal(k.sha256, digest)) found = &u;  // no early exit: time says nothing
    }
  }
  return found;
}

}  // namespace cncd::web
