# The browser page of cncd-web: plain files and ES modules, copied as they are (no build step)
# into ${PROJECT_BINARY_DIR}/share/cncd/www, where cncd-web finds them beside its binary, and
# installed to ${CMAKE_INSTALL_DATADIR}/cncd/www. three.js is Debian's libjs-three, copied at
# build time (web/www/VENDORED.md): nothing is fetched from the network, at build or run time.
set(CNCD_WWW_DIR ${PROJECT_BINARY_DIR}/share/cncd/www)
set(CNCD_THREE_DIR /usr/share/javascript/three CACHE PATH "Debian libjs-three's directory")

find_file(CNCD_THREE_MODULE three.module.js PATHS ${CNCD_THREE_DIR}/build NO_DEFAULT_PATH)
find_file(CNCD_THREE_ORBIT OrbitControls.js PATHS ${CNCD_THREE_DIR}/examples/jsm/controls
          NO_DEFAULT_PATH)
if(NOT CNCD_THREE_MODULE OR NOT CNCD_THREE_ORBIT)
  message(FATAL_ERROR "cncd-web's page needs three.js from Debian's libjs-three "
                      "(${CNCD_THREE_DIR}/build/three.module.js and "
                      "examples/jsm/controls/OrbitControls.js): apt install libjs-three, "
                      "or set CNCD_THREE_DIR")
endif()
set(CNCD_THREE_COPYRIGHT /usr/share/doc/libjs-three/copyright)

# The page's own files (documentation .md and this file stay behind).
file(GLOB CNCD_WWW_PAGE CONFIGURE_DEPENDS RELATIVE ${CMAKE_CURRENT_LIST_DIR}
     ${CMAKE_CURRENT_LIST_DIR}/*.html ${CMAKE_CURRENT_LIST_DIR}/*.css
     ${CMAKE_CURRENT_LIST_DIR}/*.js ${CMAKE_CURRENT_LIST_DIR}/*.svg
     ${CMAKE_CURRENT_LIST_DIR}/js/*.js)

set(CNCD_WWW_OUTPUTS)
# Copies SOURCE to RELATIVE under the www directory, again whenever SOURCE changes.
function(cncd_www_copy source relative)
  set(out ${CNCD_WWW_DIR}/${relative})
  add_custom_command(OUTPUT ${out}
                     COMMAND ${CMAKE_COMMAND} -E copy ${source} ${out}
                     DEPENDS ${source}
                     COMMENT "www: ${relative}"
                     VERBATIM)
  set(CNCD_WWW_OUTPUTS ${CNCD_WWW_OUTPUTS} ${out} PARENT_SCOPE)
endfunction()

foreach(file IN LISTS CNCD_WWW_PAGE)
  cncd_www_copy(${CMAKE_CURRENT_LIST_DIR}/${file} ${file})
endforeach()
# OrbitControls imports "../../../build/three.module.js": keep Debian's layout below vendor/.
cncd_www_copy(${CNCD_THREE_MODULE} vendor/three/build/three.module.js)
cncd_www_copy(${CNCD_THREE_ORBIT} vendor/three/examples/jsm/controls/OrbitControls.js)
if(EXISTS ${CNCD_THREE_COPYRIGHT})
  cncd_www_copy(${CNCD_THREE_COPYRIGHT} vendor/three/copyright)
endif()
cncd_www_copy(${CMAKE_CURRENT_LIST_DIR}/VENDORED.md vendor/VENDORED.md)

add_custom_target(cncd_www ALL DEPENDS ${CNCD_WWW_OUTPUTS})

install(DIRECTORY ${CNCD_WWW_DIR}/ DESTINATION ${CMAKE_INSTALL_DATADIR}/cncd/www)
