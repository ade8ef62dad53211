# The program and protocol versions (version.hpp), shared by the daemon and its clients.
if(NOT TARGET cncd_version)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/version.hpp.in
                 ${CMAKE_BINARY_DIR}/generated/version.hpp @ONLY)
  add_library(cncd_version INTERFACE)
  target_include_directories(cncd_version INTERFACE ${CMAKE_BINARY_DIR}/generated)
endif()
