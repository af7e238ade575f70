# Warnings in one place, for every target of ours.
function(colmap_lidar_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wno-unused-parameter
                                           -Wno-sign-compare)
endfunction()

# colmap_lidar_add_test(NAME module/name SOURCES a_test.cc LINKS lib...)
# registers one GoogleTest executable in ctest under the given name prefix.
function(colmap_lidar_add_test)
  # COST: CTest starts costlier tests first under -j, so that a long integration test does not run
  # alone at the end (a clean checkout has no timing history to order by).
  cmake_parse_arguments(ARG "" "NAME;COST" "SOURCES;LINKS" ${ARGN})
  if(NOT ARG_COST)
    set(ARG_COST 0)
  endif()
  string(REPLACE "/" "_" exe ${ARG_NAME})
  add_executable(${exe} ${ARG_SOURCES})
  target_link_libraries(${exe} PRIVATE ${ARG_LINKS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${exe} PRIVATE
    COLMAP_LIDAR_COLMAP_EXE="${COLMAP_LIDAR_COLMAP_EXE}"
    COLMAP_LIDAR_CLI_EXE="${CMAKE_BINARY_DIR}/bin/colmap-lidar")
  colmap_lidar_set_warnings(${exe})
  set_target_properties(${exe} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  gtest_discover_tests(${exe} TEST_PREFIX "${ARG_NAME}/" DISCOVERY_TIMEOUT 60
                       PROPERTIES TIMEOUT 1200 COST ${ARG_COST})
endfunction()
