// The users file: argon2id passwords, API keys stored as hashes, the file's rules.
#include "cncd/web/users.hpp"

#include <gtest/gtest.h>
#include <openssl/evp.h>
#include <sys/stat.h>

#include <array>

#include "temp_dir.hpp"

namespace cncd::web {
namespace {

// Cheap enough for tests; the default is RFC 9106's.
constexpr PasswordCost kCheap{1, 64, 1};

std::string sha256_hex(const std::string& data) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
  unsigned int n = 0;
  EVP_Digest(data.data(), data.size(), md.data(), &n, EVP_sha256(), nullptr);
  std::string out;
  char byte[3];
  for (unsigned int i = 0; i < n; ++i) {
    std::snprintf(byte, sizeof byte, "%02x", md[i]);
    out += byte;
  }
  return out;
}

mode_t mode_of(const std::filesystem::path& path) {
  struct stat st {};
  EXPECT_EQ(::stat(path.c_str(), &st), 0);
  return st.st_mode & 07777;
}

TEST(PasswordTest, Argon2idHashesVerifyTheirPasswordOnly) {
  const std::string hash = hash_password("correct horse", kCheap);
  EXPECT_TRUE(hash.starts_with("$argon2id$v=19$m=64,t=1,p=1$")) << hash;
  EXPECT_TRUE(verify_password(hash, "correct horse"));
  EXPECT_FALSE(verify_password(hash, "correct horse "));
  EXPECT_FALSE(verify_password(hash, ""));
  EXPECT_NE(hash_password("correct horse", kCheap), hash);  // salted
  EXPECT_FALSE(verify_password("-", "x"));
  EXPECT_FALSE(verify_password("$argon2id$garbage", "x"));
  EXPECT_FALSE(verify_password("$argon2i$v=19$m=64,t=1,p=1$c2FsdHNhbHQ$aGFzaA", "x"));
}

TEST(PasswordTest, TheDefaultCostIsRfc9106s) {
  const std::string hash = hash_password("pw");
  EXPECT_TRUE(hash.starts_with("$argon2id$v=19$m=65536,t=3,p=1$")) << hash;
  EXPECT_TRUE(verify_password(hash, "pw"));
}

TEST(PasswordTest, NameAndPasswordRules) {
  for (const std::string& ok :
       std::vector<std::string>{"a", "alice", "A.b-c_9", std::string(32, 'x')}) {
    EXPECT_EQ(check_user_name(ok), "") << ok;
  }
  EXPECT_EQ(check_user_name(""), "a user name may not be empty");
  EXPECT_EQ(check_user_name(std::string(33, 'x')), "a user name has at most 32 characters");
  for (const std::string bad : {"a b", "a/b", "../x", "al:ce", "\xc3\xa9", "a\nb"}) {
    EXPECT_EQ(check_user_name(bad), "a user name has only letters, digits, '_', '.' and '-'")
        << bad;
  }
  EXPECT_EQ(check_password(""), "the password is empty");
  EXPECT_EQ(check_password("a\nb"), "the password contains a NUL, CR or LF");
  EXPECT_EQ(check_password(std::string("a\0b", 3)), "the password contains a NUL, CR or LF");
  EXPECT_EQ(check_password(std::string(1025, 'p')), "the password is longer than 1024 bytes");
  EXPECT_EQ(check_password("pässword with spaces"), "");
}

using UsersFileTest = test::TempDirTest;

TEST_F(UsersFileTest, SavedUsersComeBackWithTheirPasswordsAndKeys) {
  const auto path = dir_ / "state/web-users";  // the directory is created
  UsersFile users(path, kCheap);
  ASSERT_EQ(users.load(), "");  // missing: no users
  EXPECT_TRUE(users.users().empty());
  ASSERT_EQ(users.add("alice", Role::operator_, "s3cret"), "");
  ASSERT_EQ(users.add("root.admin", Role::admin, "other"), "");
  EXPECT_EQ(users.add("alice", Role::admin, "x"), "user 'alice' exists already");
  EXPECT_EQ(users.add("bad name", Role::admin, "x"),
            "a user name has only letters, digits, '_', '.' and '-'");
  std::string error;
  const auto key = users.add_key("alice", error);
  ASSERT_TRUE(key) << error;
  EXPECT_TRUE(key->key.starts_with("cncd_")) << key->key;
  EXPECT_EQ(key->key.size(), 5u + 43u);  // 32 bytes in base64url without padding
  EXPECT_EQ(key->key.find_first_not_of(
                "cnd_ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-", 5),
            std::string::npos);
  EXPECT_EQ(key->id.size(), 8u);
  EXPECT_FALSE(users.add_key("nobody", error));
  EXPECT_EQ(error, "no user 'nobody'");
  ASSERT_EQ(users.save(), "");
  EXPECT_EQ(mode_of(path), 0600u);
  EXPECT_EQ(mode_of(dir_ / "state"), 0700u);
  EXPECT_FALSE(users.changed_on_disk());

  const std::string text = read(path);
  EXPECT_EQ(text.find(key->key), std::string::npos) << "the key itself is never stored";
  EXPECT_EQ(text.find(key->key.substr(5)), std::string::npos);
  EXPECT_NE(text.find("key:" + key->id + ":" + sha256_hex(key->key)), std::string::npos) << text;
  EXPECT_EQ(text.find("s3cret"), std::string::npos);
  for (const auto& entry : std::filesystem::directory_iterator(dir_ / "state")) {
    EXPECT_EQ(entry.path(), path) << "a temporary file was left behind";
  }

  UsersFile again(path, kCheap);
  ASSERT_EQ(again.load(), "");
  ASSERT_EQ(again.users().size(), 2u);
  EXPECT_EQ(again.find("alice")->role, Role::operator_);
  EXPECT_EQ(again.find("root.admin")->role, Role::admin);
  EXPECT_EQ(again.check_password("alice", "s3cret"), again.find("alice"));
  EXPECT_EQ(again.check_password("alice", "other"), nullptr);
  EXPECT_EQ(again.check_password("nobody", "s3cret"), nullptr);
  EXPECT_EQ(again.check_key(key->key), again.find("alice"));
  EXPECT_EQ(again.check_key(key->key.substr(0, 47) + (key->key[47] == 'A' ? "B" : "A")), nullptr);
  EXPECT_EQ(again.check_key(""), nullptr);
  EXPECT_EQ(again.check_key(key->key.substr(5)), nullptr);  // without its prefix

  ASSERT_EQ(again.set_password("alice", "new one"), "");
  EXPECT_EQ(again.remove_key("alice", "00000000"), "user 'alice' has no key 00000000");
  ASSERT_EQ(again.remove_key("alice", key->id), "");
  ASSERT_EQ(again.remove("root.admin"), "");
  EXPECT_EQ(again.remove("root.admin"), "no user 'root.admin'");
  ASSERT_EQ(again.save(), "");
  EXPECT_TRUE(users.changed_on_disk());  // the first copy sees the other's save
  ASSERT_EQ(users.load(), "");
  EXPECT_EQ(users.users().size(), 1u);
  EXPECT_EQ(users.check_key(key->key), nullptr);
  EXPECT_EQ(users.check_password("alice", "s3cret"), nullptr);
  EXPECT_NE(users.check_password("alice", "new one"), nullptr);
}

TEST_F(UsersFileTest, AFileOthersMayReadIsRefusedNamingItsMode) {
  const auto path = write(dir_ / "users", "alice admin -\n");
  for (const mode_t mode : {0644, 0640, 0604, 0620, 0602}) {
    ::chmod(path.c_str(), mode);
    UsersFile users(path, kCheap);
    char text[8];
    std::snprintf(text, sizeof text, "%04o", mode);
    EXPECT_EQ(users.load(), path.string() + ": mode " + text +
                                " lets the group or others at the password hashes; chmod 600 " +
                                path.string());
    EXPECT_TRUE(users.users().empty());
  }
  ::chmod(path.c_str(), 0600);
  UsersFile users(path, kCheap);
  EXPECT_EQ(users.load(), "");
  EXPECT_EQ(users.users().size(), 1u);
  ::mkdir((dir_ / "dir").c_str(), 0700);
  EXPECT_EQ(UsersFile(dir_ / "dir").load(), (dir_ / "dir").string() + ": not a regular file");
}

TEST_F(UsersFileTest, AMalformedLineIsRefusedNamingFileAndLine) {
  const std::string hash = hash_password("pw", kCheap);
  const std::string key = "key:0123abcd:" + std::string(64, 'e');
  const std::vector<std::pair<std::string, std::string>> cases{
      {"alice admin", "expected NAME ROLE PASSWORD_HASH [key:ID:SHA256]..."},
      {"alice boss -", "'boss' is not a role (observer|operator|setter|admin)"},
      {"al/ce admin -", "'al/ce': a user name has only letters, digits, '_', '.' and '-'"},
      {"alice admin secret",
       "the password hash is neither '-' nor an argon2id hash ($argon2id$...)"},
      {"alice admin - key:0123abcd:ABC",
       "'key:0123abcd:ABC' is not key:ID:SHA256 (8 and 64 lower-case hex digits)"},
      {"alice admin - " + key + " " + key, "key id 0123abcd appears twice"},
      {"root admin -", "user 'root' appears twice"},
  };
  for (const auto& [line, message] : cases) {
    const auto path = write(dir_ / "users", "# users\n\nroot admin " + hash + "\n" + line + "\n");
    ::chmod(path.c_str(), 0600);
    UsersFile users(path, kCheap);
    EXPECT_EQ(users.load(), path.string() + ":4: " + message) << line;
    EXPECT_TRUE(users.users().empty()) << line;
  }
}

TEST_F(UsersFileTest, AUserWithoutPasswordOnlyUsesKeys) {
  const auto path = write(dir_ / "users", "cam setter -\n");
  ::chmod(path.c_str(), 0600);
  UsersFile users(path, kCheap);
  ASSERT_EQ(users.load(), "");
  EXPECT_EQ(users.check_password("cam", "-"), nullptr);
  EXPECT_EQ(users.check_password("cam", ""), nullptr);
}

}  // namespace
}  // namespace cncd::web
