# cncd-web: the HTTP/WebSocket server (Boost.Beast), a client of cncd's socket like cncctl.
# Logging and the start shared with cncd-telemetry are cncd's own (daemon/src/logging.cpp,
# client_start.cpp, spdlog only), compiled in rather than linked from the daemon's library.
add_executable(cncd-web
  src/server/admin_entry.cpp
  src/server/app.cpp
  src/server/estimates.cpp
  src/server/http_handlers.cpp
  src/server/listener.cpp
  src/server/main.cpp
  src/server/status_watch.cpp
  src/server/web_methods.cpp
  src/server/ws_rpc.cpp
  ${PROJECT_SOURCE_DIR}/daemon/src/client_start.cpp
  ${PROJECT_SOURCE_DIR}/daemon/src/logging.cpp)
target_include_directories(cncd-web PRIVATE src/server ${PROJECT_SOURCE_DIR}/daemon/src)
target_link_libraries(cncd-web PRIVATE cncd_web_core cncd_http cncd_upstream cncd_config cncd_version cncd_asio
                                       OpenSSL::SSL spdlog::spdlog nlohmann_json::nlohmann_json)
set_target_properties(cncd-web PROPERTIES RUNTIME_OUTPUT_DIRECTORY "${CNCD_BIN_DIR}")
# The page's target is made after this file (web/www/www.cmake): checked at the end.
function(cncd_web_needs_www)
  if(TARGET cncd_www)
    add_dependencies(cncd-web cncd_www)
  endif()
endfunction()
cmake_language(DEFER CALL cncd_web_needs_www)
install(TARGETS cncd-web RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
