# Writes OUT: one add_test per GoogleTest suite that EXE lists, labelled LABEL, run in WORKDIR.
# Run by rovo_add_gtest_suites (cmake/gtest_suites.cmake) after each build of EXE.
execute_process(COMMAND "${EXE}" --gtest_list_tests OUTPUT_VARIABLE listing RESULT_VARIABLE status
                TIMEOUT 60)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed (${status})")
endif()
# Suite lines start in column 0 and end the suite's name with a dot ("Suite." or "Param/Suite.  # ...").
string(REPLACE ";" "," listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(content "")
foreach(line IN LISTS lines)
  if(line MATCHES "^([A-Za-z0-9_/]+)\\.( |$)")
    set(suite "${CMAKE_MATCH_1}")
    string(APPEND content
           "add_test([=[${suite}]=] [==[${EXE}]==] [=[--gtest_filter=${suite}.*]=])\n"
           "set_tests_properties([=[${suite}]=] PROPERTIES LABELS ${LABEL} WORKING_DIRECTORY [==[${WORKDIR}]==])\n")
  endif()
endforeach()
if(content STREQUAL "")
  message(FATAL_ERROR "${EXE} --gtest_list_tests listed no suite")
endif()
file(WRITE "${OUT}" "${content}")
