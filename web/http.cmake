# cncd_http: what cncd's HTTP servers share (cncd-web, cncd-fleet): accepting connections, JSON
# answers, static files of a page directory and the bounded outbox of a WebSocket.
add_library(cncd_http src/http/accept_loop.cpp src/http/http_common.cpp)
target_include_directories(cncd_http PUBLIC src/http)
target_link_libraries(cncd_http PUBLIC cncd_asio nlohmann_json::nlohmann_json
                                PRIVATE cncd_web_core spdlog::spdlog)
