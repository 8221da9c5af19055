# Every doctest case runs under CTest: doctest_discover_tests registers each case by its
# name, and a name holding a semicolon (a CMake list separator) is cut there — the test
# then selects no case and passes without running anything. Run as a test:
#   cmake -DROOT=<source dir> -P tests/check_test_names.cmake
file(GLOB_RECURSE sources "${ROOT}/tests/*.cpp")
set(problems "")
foreach(source ${sources})
  file(STRINGS "${source}" cases REGEX "TEST_CASE\\(\"[^\"]*;")
  foreach(line ${cases})
    file(RELATIVE_PATH where "${ROOT}" "${source}")
    string(STRIP "${line}" line)
    string(APPEND problems "  ${where}: ${line}\n")
  endforeach()
endforeach()
if(problems)
  message(FATAL_ERROR "test cases whose names hold a semicolon (CTest would run none of them):\n${problems}")
endif()
