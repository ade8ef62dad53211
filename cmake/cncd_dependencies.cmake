# The libraries cncd builds against, found once for the main build and the standalone fuzz
# build alike.
find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)
find_package(spdlog REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(OpenSSL 3 REQUIRED)  # libcrypto: base64 of binary payloads
pkg_check_modules(MODBUS REQUIRED IMPORTED_TARGET libmodbus)
pkg_check_modules(GPIOD REQUIRED IMPORTED_TARGET libgpiod)
pkg_check_modules(SYSTEMD REQUIRED IMPORTED_TARGET libsystemd)
