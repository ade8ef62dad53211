# The page in a real headless Chromium (Debian's chromium and chromium-driver, driven by
# python3-selenium) against the real cncd on the simulated mill (the trunnion for TCP) and the
# real cncd-web. Without them the tests say what is missing and are skipped (exit 77);
# scripts/setup.sh --with-browser installs them. Debian's selenium lives in the system Python,
# so /usr/bin's python3 is preferred to another one earlier in PATH.
find_program(CNCD_SYSTEM_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT CNCD_SYSTEM_PYTHON3)
  find_program(CNCD_SYSTEM_PYTHON3 NAMES python3)
endif()

foreach(name operator access tcp)
  set(test web.browser.${name})
  if(CNCD_SYSTEM_PYTHON3 AND TARGET cncd-web)
    add_test(NAME ${test}
             COMMAND ${CNCD_SYSTEM_PYTHON3} ${CMAKE_CURRENT_SOURCE_DIR}/browser_${name}_test.py
                     --cncd $<TARGET_FILE:cncd> --cncd-web $<TARGET_FILE:cncd-web>
                     --source-dir ${PROJECT_SOURCE_DIR}
                     --out-dir ${CMAKE_CURRENT_BINARY_DIR}/browser)
  else()
    add_test(NAME ${test}
             COMMAND sh -c "echo 'SKIP: no python3 or no cncd-web target'; exit 77")
  endif()
  # One browser at a time, with both cores: a loaded machine slows the page, and the jog stop
  # is measured against a wall clock.
  set_tests_properties(${test} PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 600 PROCESSORS 2
                       RESOURCE_LOCK cncd_browser ENVIRONMENT PYTHONDONTWRITEBYTECODE=1)
endforeach()
