# The fleet page in a real headless Chromium (as tests/web/browser.cmake: Debian's chromium,
# chromium-driver and python3-selenium; without them, or without mosquitto, skipped with exit
# 77) against three real cncd on the simulated mill, their cncd-telemetry, one broker and
# cncd-fleet.
find_program(CNCD_FLEET_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT CNCD_FLEET_PYTHON3)
  find_program(CNCD_FLEET_PYTHON3 NAMES python3)
endif()
if(CNCD_FLEET_PYTHON3)
  add_test(NAME fleet.browser.three_machines
           COMMAND ${CNCD_FLEET_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/browser_fleet_test.py
                   --cncd $<TARGET_FILE:cncd> --cncd-telemetry $<TARGET_FILE:cncd-telemetry>
                   --cncd-fleet $<TARGET_FILE:cncd-fleet>
                   --fleet-www ${PROJECT_BINARY_DIR}/share/cncd/fleet-www
                   --source-dir ${PROJECT_SOURCE_DIR}
                   --out-dir ${CMAKE_CURRENT_BINARY_DIR}/browser)
else()
  add_test(NAME fleet.browser.three_machines
           COMMAND sh -c "echo 'SKIP: no python3'; exit 77")
endif()
set_tests_properties(fleet.browser.three_machines PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300
                     PROCESSORS 2 RESOURCE_LOCK cncd_browser
                     ENVIRONMENT PYTHONDONTWRITEBYTECODE=1)
