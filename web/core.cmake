# cncd_web_core: users, roles, sessions, the login limiter, the control lease and the program
# directory of cncd-web, without any network code (the server links it; tests use it alone).
add_library(cncd_web_core INTERFACE)
target_include_directories(cncd_web_core INTERFACE ${CMAKE_CURRENT_SOURCE_DIR}/include)
target_link_libraries(cncd_web_core INTERFACE cncd_config)
