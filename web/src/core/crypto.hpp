// The few cryptographic primitives cncd-web needs, from OpenSSL (not installed).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace cncd::web::crypto {

// `count` bytes from OpenSSL's CSPRNG (RAND_bytes); throws std::runtime_error when it fails.
std::string random_bytes(std::size_t count);
// Lower-case hex of `bytes`.
std::string hex(std::string_view bytes);
// base64url without padding (RFC 4648 section 5).
std::string base64url(std::string_view bytes);
// Lower-case hex of the SHA-256 of `data`.
std::string sha256_hex(std::string_view data);
// Equality whose time depends only on the lengths.
bool equal(std::string_view a, std::string_view b);

}  // namespace cncd::web::crypto
