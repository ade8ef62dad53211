# cncd_web_core alone: users file, command line, roles, sessions, lease, program directory.
add_executable(cncd_web_core_test
  core/admin_cli_test.cpp
  core/lease_test.cpp
  core/program_dir_test.cpp
  core/program_names_test.cpp
  core/roles_test.cpp
  core/sessions_test.cpp
  core/users_test.cpp
)
target_link_libraries(cncd_web_core_test PRIVATE cncd_web_core OpenSSL::Crypto GTest::gtest_main)
gtest_discover_tests(cncd_web_core_test TEST_PREFIX "web.core." DISCOVERY_TIMEOUT 60)
