// cncd-web's users: names, roles, argon2id password hashes and API key hashes, kept in
// [WEB] USERS_FILE. The file holds no secret in the clear: a stolen copy gives neither a
// password nor a key.
//
// Format: text, one user per line, '#' starts a comment line, blank lines ignored:
//   NAME ROLE PASSWORD_HASH [key:ID:SHA256HEX]...
// PASSWORD_HASH is argon2id's encoded form ($argon2id$v=19$m=...,t=...,p=...$SALT$HASH) or
// "-" (no password: the user can only use API keys). ID is 8 hex digits naming the key in
// `user list` and `key del`; SHA256HEX the SHA-256 of the key as shown once ("cncd_...").
#pragma once

#include <sys/stat.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cncd/web/roles.hpp"

namespace cncd::web {

// argon2id cost. The default follows RFC 9106's second recommendation (t=3, 64 MiB, p=1,
// about 0.1-0.3 s per hash on a small ARM or x86 box); tests pass a cheap one.
struct PasswordCost {
  std::uint32_t time_cost = 3;
  std::uint32_t memory_kib = 64 * 1024;
  std::uint32_t parallelism = 1;
};

// argon2id encoded hash of `password` with a fresh 16-byte random salt. Throws
// std::runtime_error only when libargon2 fails (out of memory).
std::string hash_password(std::string_view password, const PasswordCost& cost = {});
// True when `password` matches the encoded hash (whatever cost it was made with); false for
// "-" or a malformed hash. Takes as long as the hash's cost: call it off a latency-critical
// thread.
bool verify_password(std::string_view encoded, std::string_view password);

// "" when `name` is a valid user name ([A-Za-z0-9_.-]{1,32}), else why not.
std::string check_user_name(std::string_view name);
// "" when `password` is acceptable (1..1024 bytes, no NUL, CR or LF), else why not.
std::string check_password(std::string_view password);

struct ApiKeyHash {
  std::string id;      // 8 hex digits
  std::string sha256;  // 64 lower-case hex digits
};

struct User {
  std::string name;
  Role role = Role::observer;
  std::string password_hash;  // argon2id encoded, or "-"
  std::vector<ApiKeyHash> keys;
};

// A key as its user sees it once: "cncd_" + base64url of 32 random bytes (48 characters).
struct NewApiKey {
  std::string id;
  std::string key;
};

// A password already hashed by hash_password() (with the file's cost()), so that the slow
// hashing can run away from the thread that owns the file.
struct HashedPassword {
  std::string encoded;
};

// The users file in memory. Not thread-safe: the owner serialises access.
class UsersFile {
 public:
  explicit UsersFile(std::filesystem::path path, PasswordCost cost = {});

  const std::filesystem::path& path() const { return path_; }
  const PasswordCost& cost() const { return cost_; }

  // Reads the file, replacing what is in memory. A missing file is no users (""). Refused
  // (the message names the file and, where it applies, the line or the mode): a file that the
  // group or others may read or write ("... mode 0644: others may read it; chmod 600 ..."),
  // one that is not a regular file, a malformed line, a duplicate user.
  // Returns "" on success, else the message (memory is then unchanged).
  std::string load();
  // True when the file on disk is not the one last loaded or saved (another process, e.g. the
  // command line, changed it): the owner reloads.
  bool changed_on_disk() const;
  // Writes all users: a temporary file in the same directory (mode 0600), fsync, rename over
  // the file, fsync of the directory; the directory is created (0700) when missing.
  // Returns "" or the message.
  std::string save();

  const std::vector<User>& users() const { return users_; }
  const User* find(std::string_view name) const;

  // Edits in memory (save() writes them). Each returns "" or why not (bad or duplicate name,
  // unknown user, bad password, unknown key id).
  std::string add(std::string_view name, Role role, std::string_view password);
  std::string remove(std::string_view name);
  std::string set_password(std::string_view name, std::string_view password);
  // The same with the hash made beforehand (the password's rules were checked then).
  std::string add(std::string_view name, Role role, HashedPassword hash);
  std::string set_password(std::string_view name, HashedPassword hash);
  std::string set_role(std::string_view name, Role role);
  // A new key for `name` (the key itself is never stored); nullopt with `error` set when the
  // user is unknown.
  std::optional<NewApiKey> add_key(std::string_view name, std::string& error);
  std::string remove_key(std::string_view name, std::string_view id);

  // The user whose password this is; nullptr when the name is unknown or the password wrong.
  // An unknown name costs as long as a wrong password, so timing tells no names apart.
  const User* check_password(std::string_view name, std::string_view password) const;
  // The user holding this API key ("cncd_..."); compared by SHA-256 in constant time.
  const User* check_key(std::string_view key) const;

 private:
  User* entry(std::string_view name);

  std::filesystem::path path_;
  PasswordCost cost_;
  std::vector<User> users_;
  // Identity of the file last loaded or saved, for changed_on_disk().
  struct Stamp {
    bool exists = false;
    dev_t dev = 0;
    ino_t ino = 0;
    std::int64_t size = 0;
    std::int64_t mtime_ns = 0;
  };
  Stamp stamp_;
  mutable std::string dummy_hash_;  // verified against for unknown names
};

}  // namespace cncd::web
