// argon2id hashes and the rules for user names and passwords.
#include <argon2.h>

#include <stdexcept>
#include <string>

#include "cncd/web/users.hpp"
#include "crypto.hpp"

namespace cncd::web {
namespace {

constexpr std::size_t kSaltBytes = 16;
constexpr std::size_t kHashBytes = 32;

}  // namespace

std::string hash_password(std::string_view password, const PasswordCost& cost) {
  const std::string salt = crypto::random_bytes(kSaltBytes);
  std::string encoded(argon2_encodedlen(cost.time_cost, cost.memory_kib, cost.parallelism,
                                        kSaltBytes, kHashBytes, Argon2_id),
                      '\0');
  const int rc = argon2id_hash_encoded(cost.time_cost, cost.memory_kib, cost.parallelism,
                                       password.data(), password.size(), salt.data(), salt.size(),
                                       kHashBytes, encoded.data(), encoded.size());
  if (rc != ARGON2_OK) {
    throw std::runtime_error(std::string("argon2id failed: ") + argon2_error_message(rc));
  }
  encoded.resize(encoded.find('\0'));
  return encoded;
}

bool verify_password(std::string_view encoded, std::string_view password) {
  if (!encoded.starts_with("$argon2id$")) return false;
  const std::string terminated(encoded);
  return argon2id_verify(terminated.c_str(), password.data(), password.size()) == ARGON2_OK;
}

std::string check_user_name(std::string_view name) {
  if (name.empty()) return "a user name may not be empty";
  if (name.size() > 32) return "a user name has at most 32 characters";
  for (const char c : name) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '.' || c == '-';
    if (!ok) return "a user name has only letters, digits, '_', '.' and '-'";
  }
  return "";
}

std::string check_password(std::string_view password) {
  if (password.empty()) return "the password is empty";
  if (password.size() > 1024) return "the password is longer than 1024 bytes";
  if (password.find_first_of(std::string_view("\0\r\n", 3)) != std::string_view::npos) {
    return "the password contains a NUL, CR or LF";
  }
  return "";
}

}  // namespace cncd::web
