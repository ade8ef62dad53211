# The libraries cncd builds against, found once for the main build and the standalone fuzz
# build alike.
find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)
find_package(spdlog REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(OpenSSL 3 REQUIRED)  # libcrypto: base64 of binary payloads, SHA-256
pkg_check_modules(MODBUS REQUIRED IMPORTED_TARGET libmodbus)
pkg_check_modules(GPIOD REQUIRED IMPORTED_TARGET libgpiod)
pkg_check_modules(SYSTEMD REQUIRED IMPORTED_TARGET libsystemd)
# The daemon's job history.
pkg_check_modules(SQLITE3 REQUIRED IMPORTED_TARGET sqlite3)
# cncd-telemetry's MQTT.
pkg_check_modules(MOSQUITTO REQUIRED IMPORTED_TARGET libmosquitto)
# cncd-web: HTTP and WebSocket from Boost.Beast (header-only), passwords hashed with argon2id.
find_package(Boost 1.81 REQUIRED)
# What cncd-web and its tests build Asio with. ThreadSanitizer does not model standalone
# fences, and GCC refuses the one Asio puts around each handler (-Wtsan); Asio's queues are
# guarded by mutexes, which it does model, so that build leaves the fence out.
add_library(cncd_asio INTERFACE)
target_link_libraries(cncd_asio INTERFACE Boost::headers)
if(CMAKE_CXX_FLAGS MATCHES "-fsanitize=thread")
  target_compile_definitions(cncd_asio INTERFACE BOOST_ASIO_DISABLE_FENCED_BLOCK)
endif()
pkg_check_modules(ARGON2 REQUIRED IMPORTED_TARGET libargon2)
