# cncd-web against the real daemon on the simulated mill: HTTP, login, files, /ws, the lease.
add_executable(cncd_web_server_test server/web_client.cpp server/server_http_test.cpp
                                    server/server_ws_test.cpp server/server_robustness_test.cpp
                                    server/server_backpressure_test.cpp)
target_include_directories(cncd_web_server_test PRIVATE server)
target_link_libraries(cncd_web_server_test PRIVATE cncd_client cncd_test_support cncd_asio
                                                   nlohmann_json::nlohmann_json GTest::gtest_main)
target_compile_definitions(cncd_web_server_test PRIVATE
  CNCD_WEB_BINARY="$<TARGET_FILE:cncd-web>")
add_dependencies(cncd_web_server_test cncd-web)
gtest_discover_tests(cncd_web_server_test TEST_PREFIX "web." PROPERTIES TIMEOUT 120)
