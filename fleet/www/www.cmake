# The fleet page: plain files and one ES module, copied as they are (no build step, nothing
# fetched) into ${PROJECT_BINARY_DIR}/share/cncd/fleet-www, where cncd-fleet finds them beside
# its binary, and installed to ${CMAKE_INSTALL_DATADIR}/cncd/fleet-www.
set(CNCD_FLEET_WWW_DIR ${PROJECT_BINARY_DIR}/share/cncd/fleet-www)
file(GLOB CNCD_FLEET_PAGE CONFIGURE_DEPENDS RELATIVE ${CMAKE_CURRENT_LIST_DIR}
     ${CMAKE_CURRENT_LIST_DIR}/*.html ${CMAKE_CURRENT_LIST_DIR}/*.css
     ${CMAKE_CURRENT_LIST_DIR}/*.js)
set(outputs)
foreach(file IN LISTS CNCD_FLEET_PAGE)
  add_custom_command(OUTPUT ${CNCD_FLEET_WWW_DIR}/${file}
                     COMMAND ${CMAKE_COMMAND} -E copy ${CMAKE_CURRENT_LIST_DIR}/${file}
                             ${CNCD_FLEET_WWW_DIR}/${file}
                     DEPENDS ${CMAKE_CURRENT_LIST_DIR}/${file}
                     COMMENT "fleet-www: ${file}"
                     VERBATIM)
  list(APPEND outputs ${CNCD_FLEET_WWW_DIR}/${file})
endforeach()
add_custom_target(cncd_fleet_www ALL DEPENDS ${outputs})
install(DIRECTORY ${CNCD_FLEET_WWW_DIR}/ DESTINATION ${CMAKE_INSTALL_DATADIR}/cncd/fleet-www)
