# Install rules and the exported CMake package: after `cmake --install BUILD --prefix PREFIX`, a C++
# project links our layers with
#   find_package(colmap_lidar REQUIRED)   # CMAKE_PREFIX_PATH: PREFIX and COLMAP 3.10's prefix
#   target_link_libraries(app PRIVATE colmap_lidar::pipeline)  # or ::bridge, ::lidar, ::colmap_ext, ::util
# The CLI installs to PREFIX/bin/colmap-lidar; headers to PREFIX/include/{lidar,colmap_ext,bridge}.
include(CMakePackageConfigHelpers)
include(GNUInstallDirs)

set_target_properties(colmap_lidar_util PROPERTIES EXPORT_NAME util)
set_target_properties(colmap_lidar_lidar PROPERTIES EXPORT_NAME lidar)
set_target_properties(colmap_lidar_colmap_ext PROPERTIES EXPORT_NAME colmap_ext)
set_target_properties(colmap_lidar_bridge PROPERTIES EXPORT_NAME bridge)
set_target_properties(colmap_lidar_pipeline PROPERTIES EXPORT_NAME pipeline)
install(TARGETS colmap_lidar_util colmap_lidar_lidar colmap_lidar_colmap_ext colmap_lidar_bridge
                colmap_lidar_pipeline
        EXPORT colmap_lidarTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS colmap_lidar_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
foreach(layer lidar colmap_ext bridge)
  # The commands' headers (bridge/exe) are the CLI's own, not an API.
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${layer} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          FILES_MATCHING PATTERN "*.h" PATTERN "exe" EXCLUDE)
endforeach()

set(kConfigDir ${CMAKE_INSTALL_LIBDIR}/cmake/colmap_lidar)
install(EXPORT colmap_lidarTargets NAMESPACE colmap_lidar:: DESTINATION ${kConfigDir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/colmap_lidarConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/colmap_lidarConfig.cmake
                              INSTALL_DESTINATION ${kConfigDir})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/colmap_lidarConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/colmap_lidarConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/colmap_lidarConfigVersion.cmake
        DESTINATION ${kConfigDir})
