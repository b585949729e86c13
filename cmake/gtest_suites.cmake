# rovo_add_gtest_suites(TARGET LABEL): one ctest test per GoogleTest suite of TARGET (named after the
# suite, run as `TARGET --gtest_filter=Suite.*`), labelled LABEL. Unlike gtest_discover_tests (one
# process per test), a suite's tests share one process: the test executables load some 260 shared
# libraries (about 0.5 s each start), and a fixture's SetUpTestSuite (a rendered dataset, a suite run,
# an export) runs once for all its tests. The suites are listed after each build by
# cmake/gtest_suites_list.cmake, so ctest sees new tests without a reconfigure.
function(rovo_add_gtest_suites target label)
  set(suites_file "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites.cmake")
  set(include_file "${CMAKE_CURRENT_BINARY_DIR}/${target}_include.cmake")
  add_custom_command(
    TARGET ${target} POST_BUILD
    COMMAND ${CMAKE_COMMAND} -D "EXE=$<TARGET_FILE:${target}>" -D "OUT=${suites_file}" -D "LABEL=${label}"
            -D "WORKDIR=${CMAKE_CURRENT_BINARY_DIR}" -P ${PROJECT_SOURCE_DIR}/cmake/gtest_suites_list.cmake
    BYPRODUCTS ${suites_file}
    VERBATIM)
  file(WRITE ${include_file}
       "if(EXISTS \"${suites_file}\")\n  include(\"${suites_file}\")\n"
       "else()\n  add_test(${target}_NOT_BUILT ${target}_NOT_BUILT)\nendif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${include_file})
endfunction()
