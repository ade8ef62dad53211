# cncd_web_core: users, roles, sessions, the login limiter, the control lease and the program
# directory of cncd-web, without any network code (the server links it; tests use it alone).
add_library(cncd_web_core
  src/core/admin_cli.cpp
  src/core/crypto.cpp
  src/core/lease.cpp
  src/core/passwords.cpp
  src/core/program_dir.cpp
  src/core/program_names.cpp
  src/core/roles.cpp
  src/core/sessions.cpp
  src/core/upload.cpp
  src/core/users.cpp
)
target_include_directories(cncd_web_core PUBLIC include PRIVATE src/core)
target_link_libraries(cncd_web_core PUBLIC cncd_config PRIVATE PkgConfig::ARGON2 OpenSSL::Crypto)
