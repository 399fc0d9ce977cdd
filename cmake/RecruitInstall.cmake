# `cmake --install build --prefix P` installs the plugin library, the MuJoCo-free libraries, their
# headers, the `recruit` program and a CMake package, so that another project can use
#   find_package(Recruit REQUIRED)   # with -DCMAKE_PREFIX_PATH=P
#   target_link_libraries(app PRIVATE Recruit::recruit_sma Recruit::recruit_estimation)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS recruit_common recruit_sma_core recruit_sma recruit_estimation
  EXPORT RecruitTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS recruit RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY src/common src/estimation DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/recruit
  FILES_MATCHING PATTERN "*.h")
install(DIRECTORY plugin/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/recruit/plugin
  FILES_MATCHING PATTERN "*.h" PATTERN "examples" EXCLUDE)
install(EXPORT RecruitTargets NAMESPACE Recruit::
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Recruit)

set(RECRUIT_INSTALL_MUJOCO_PYTHON "${MUJOCO_PYTHON}")
set(RECRUIT_INSTALL_MUJOCO_ROOT "${MUJOCO_ROOT}")
configure_package_config_file(cmake/RecruitConfig.cmake.in
  ${PROJECT_BINARY_DIR}/RecruitConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Recruit)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/RecruitConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/RecruitConfig.cmake
  ${PROJECT_BINARY_DIR}/RecruitConfigVersion.cmake cmake/FindMuJoCo.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Recruit)
