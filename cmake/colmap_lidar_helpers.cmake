# Warnings in one place, for every target of ours.
function(colmap_lidar_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wno-unused-parameter
                                           -Wno-sign-compare)
endfunction()

# colmap_lidar_add_library(NAME name SOURCES a.cc... [PUBLIC lib...] [PRIVATE lib...])
# A static library colmap_lidar_<name> with its alias colmap_lidar::<name>: the repository's root as
# its include directory (the install tree's include/ once installed), its links, our warnings.
function(colmap_lidar_add_library)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  set(target colmap_lidar_${ARG_NAME})
  add_library(${target} STATIC ${ARG_SOURCES})
  add_library(colmap_lidar::${ARG_NAME} ALIAS ${target})
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
                                              $<INSTALL_INTERFACE:include>)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
  colmap_lidar_set_warnings(${target})
endfunction()

# colmap_lidar_add_test(NAME module/name SOURCES a_test.cc LINKS lib... [FILTER gtest_filter]
#                       [LABEL unit|integration|slow] [COST seconds] [TIMEOUT seconds]
#                       [FIXTURES_SETUP name] [FIXTURES_REQUIRED name])
# builds one GoogleTest executable and registers its test cases (those matching FILTER, default all) in
# ctest under the given name prefix, each case a ctest test; colmap_lidar_discover_tests registers
# further cases of the same executable with other properties.
function(colmap_lidar_add_test)
  cmake_parse_arguments(ARG "" "NAME;COST;LABEL;FILTER;TIMEOUT;FIXTURES_SETUP;FIXTURES_REQUIRED"
                        "SOURCES;LINKS" ${ARGN})
  if(ARG_LABEL STREQUAL "slow" AND COLMAP_LIDAR_SKIP_SLOW_TESTS)
    return()
  endif()
  string(REPLACE "/" "_" exe ${ARG_NAME})
  add_executable(${exe} ${ARG_SOURCES})
  target_link_libraries(${exe} PRIVATE ${ARG_LINKS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${exe} PRIVATE
    COLMAP_LIDAR_COLMAP_EXE="${COLMAP_LIDAR_COLMAP_EXE}"
    COLMAP_LIDAR_CLI_EXE="${CMAKE_BINARY_DIR}/bin/colmap-lidar"
    COLMAP_LIDAR_TEST_FIXTURES="${CMAKE_BINARY_DIR}/test_fixtures")
  colmap_lidar_set_warnings(${exe})
  set_target_properties(${exe} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  colmap_lidar_discover_tests(TARGET ${exe} ${ARGN})
endfunction()

# colmap_lidar_discover_tests(TARGET exe NAME module/name [FILTER ...] [LABEL ...] [COST ...]
#                             [TIMEOUT seconds] [FIXTURES_SETUP name] [FIXTURES_REQUIRED name])
# LABEL (default unit): `ctest -L unit` runs the tests beside the sources; `ctest -LE slow` the quick
# set. COST: CTest starts costlier tests first under -j, so that a long test does not run alone at the
# end (a clean checkout has no timing history to order by). FIXTURES_*: CTest fixtures, for tests that
# read what another test built (it runs first, once).
function(colmap_lidar_discover_tests)
  cmake_parse_arguments(ARG "" "TARGET;NAME;COST;LABEL;FILTER;TIMEOUT;FIXTURES_SETUP;FIXTURES_REQUIRED"
                        "SOURCES;LINKS" ${ARGN})
  if(NOT ARG_COST)
    set(ARG_COST 0)
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 1200)
  endif()
  if(NOT ARG_LABEL)
    set(ARG_LABEL unit)
  endif()
  if(ARG_LABEL STREQUAL "slow" AND COLMAP_LIDAR_SKIP_SLOW_TESTS)
    return()
  endif()
  if(NOT ARG_FILTER)
    set(ARG_FILTER "*")
  endif()
  set(fixtures "")
  if(ARG_FIXTURES_SETUP)
    list(APPEND fixtures FIXTURES_SETUP ${ARG_FIXTURES_SETUP})
  endif()
  if(ARG_FIXTURES_REQUIRED)
    list(APPEND fixtures FIXTURES_REQUIRED ${ARG_FIXTURES_REQUIRED})
  endif()
  # Two tests share two cores under `ctest -j2`: OpenMP threads that wait sleep instead of spinning.
  gtest_discover_tests(${ARG_TARGET} TEST_PREFIX "${ARG_NAME}/" TEST_FILTER "${ARG_FILTER}"
                       DISCOVERY_TIMEOUT 60
                       PROPERTIES TIMEOUT ${ARG_TIMEOUT} COST ${ARG_COST} LABELS ${ARG_LABEL}
                                  ENVIRONMENT OMP_WAIT_POLICY=PASSIVE ${fixtures})
endfunction()

# colmap_lidar_needs_cli(test_target): the test runs the colmap-lidar executable, so build it first
# (no-op for a test target that is not built, see COLMAP_LIDAR_SKIP_SLOW_TESTS).
function(colmap_lidar_needs_cli target)
  if(TARGET ${target})
    add_dependencies(${target} colmap_lidar_cli)
  endif()
endfunction()
