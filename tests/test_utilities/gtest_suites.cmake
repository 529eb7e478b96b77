# Registers a googletest binary with ctest as one test per test suite (tests/CMakeLists.txt,
# hybrid_add_test_suites): the test `Suite` runs `BINARY --gtest_filter=Suite.*`, so that the
# cases of a suite share one process (its start-up, and the static data they build once). Run
# after every build of the binary (like CMake's gtest_discover_tests, which registers each case
# as a process of its own), as
#   cmake -D TEST_EXECUTABLE=... -D CTEST_FILE=... -D RC_PARAMS=... -D TIMEOUT=...
#         -D WORKING_DIRECTORY=... -D DISCOVERY_TIMEOUT=... -P gtest_suites.cmake
cmake_minimum_required(VERSION 3.25)

execute_process(
  COMMAND "${TEST_EXECUTABLE}" --gtest_list_tests
  WORKING_DIRECTORY "${WORKING_DIRECTORY}"
  TIMEOUT ${DISCOVERY_TIMEOUT}
  OUTPUT_VARIABLE output
  RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "${TEST_EXECUTABLE} --gtest_list_tests failed (${result}):\n${output}")
endif()

# A suite is a line that does not start with a space: `Suite.`, `Prefix/Suite.` (value-
# parameterized) or `Suite/0.  # TypeParam = ...` (typed); the cases below it are indented and
# may carry arbitrary text (`# GetParam() = ...`), so they go first. gtest_main's banner has
# no name followed by a dot.
string(REGEX REPLACE "\n +[^\n]*" "" output "\n${output}")
string(REGEX MATCHALL "\n[A-Za-z0-9_/]+\\." suites "${output}")

# A suite is `skipped` (ctest's Not Run) only when every case it ran was skipped: no case passed
# and nothing follows the list of skipped cases (a failure would). gtest_discover_tests' regex,
# any `[  SKIPPED ]`, would hide a failure of another case of the suite.
set(skipped [=[\[  PASSED  \] 0 tests\.
(\[  SKIPPED \] [^
]*
)+$]=])
# RC_PARAMS of the environment ctest runs in, when set, replaces the build's (`RC_PARAMS="seed=7
# max_success=2000" ctest`, tests/CMakeLists.txt).
set(script [=[if(DEFINED ENV{RC_PARAMS})
  set(rc_params "$ENV{RC_PARAMS}")
else()
]=])
string(APPEND script "  set(rc_params [==[${RC_PARAMS}]==])\nendif()\n")
foreach(suite ${suites})
  string(REGEX REPLACE "^\n(.*)\\.$" "\\1" suite "${suite}")
  string(APPEND script
    "add_test([==[${suite}]==] [==[${TEST_EXECUTABLE}]==] [==[--gtest_filter=${suite}.*]==])\n"
    "set_tests_properties([==[${suite}]==] PROPERTIES"
    " WORKING_DIRECTORY [==[${WORKING_DIRECTORY}]==]"
    " SKIP_REGULAR_EXPRESSION [==[${skipped}]==]"
    " ENVIRONMENT \"RC_PARAMS=\${rc_params}\" TIMEOUT ${TIMEOUT})\n")
endforeach()
file(WRITE "${CTEST_FILE}" "${script}")
