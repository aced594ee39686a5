# `cmake --install`: the exported targets with dualgridConfig.cmake (lib/cmake/dualgrid), the
# built networks and the scenario files (share/dualgrid), found by the installed program relative
# to its own location (bin/../share/dualgrid: sim::FindDataDir), so the tree can be moved.
include(CMakePackageConfigHelpers)
set(DUALGRID_INSTALL_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/dualgrid)
install(EXPORT dualgridTargets NAMESPACE dualgrid:: DESTINATION ${DUALGRID_INSTALL_CMAKE_DIR})
configure_package_config_file(
  ${PROJECT_SOURCE_DIR}/cmake/dualgridConfig.cmake.in ${PROJECT_BINARY_DIR}/dualgridConfig.cmake
  INSTALL_DESTINATION ${DUALGRID_INSTALL_CMAKE_DIR}
  PATH_VARS DUALGRID_INSTALL_NETWORK_DIR DUALGRID_INSTALL_SCENARIO_DIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/dualgridConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/dualgridConfig.cmake
              ${PROJECT_BINARY_DIR}/dualgridConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/dualgridDependencies.cmake
        DESTINATION ${DUALGRID_INSTALL_CMAKE_DIR})
# The networks: networks/CMakeLists.txt (where their list is known).
install(FILES ${PROJECT_SOURCE_DIR}/scenarios/simple_road.yaml
              ${PROJECT_SOURCE_DIR}/scenarios/highway.yaml ${PROJECT_SOURCE_DIR}/scenarios/soak.yaml
        DESTINATION ${DUALGRID_INSTALL_SCENARIO_DIR})
