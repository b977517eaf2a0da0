# Installs the parts of Drover that other projects build against, with an exported CMake
# package: an out-of-tree project (a vehicle integrator's RAN) does
#   find_package(drover REQUIRED)
#   target_link_libraries(my_ran PRIVATE drover::ran)
# Included from the end of the top CMakeLists.txt, after every target exists. Everything here
# is in the install component "sdk" (`cmake --install build --component sdk` installs only it).

include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(DROVER_PACKAGE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/drover)

# The exported targets and what drover::ran needs. Exported as drover::<name>.
set(_drover_exported drover_common drover_topology drover_ran)
foreach(_target IN LISTS _drover_exported)
  string(REPLACE "drover_" "" _name ${_target})
  set_target_properties(${_target} PROPERTIES EXPORT_NAME ${_name})
endforeach()

# Inside the build these come from the top CMakeLists (add_compile_definitions); users of
# the installed package need them too, as the public headers include Boost.Geometry.
target_compile_definitions(drover_topology INTERFACE
  $<INSTALL_INTERFACE:BOOST_ALLOW_DEPRECATED_HEADERS BOOST_BIND_GLOBAL_PLACEHOLDERS>)

install(TARGETS ${_drover_exported} EXPORT droverTargets COMPONENT sdk
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY
    ${PROJECT_SOURCE_DIR}/common/include/
    ${PROJECT_SOURCE_DIR}/topology/include/
    ${PROJECT_SOURCE_DIR}/ran/include/
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT sdk)

install(EXPORT droverTargets NAMESPACE drover:: DESTINATION ${DROVER_PACKAGE_DIR} COMPONENT sdk)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/droverConfig.cmake.in
  ${PROJECT_BINARY_DIR}/droverConfig.cmake
  INSTALL_DESTINATION ${DROVER_PACKAGE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/droverConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/droverConfig.cmake ${PROJECT_BINARY_DIR}/droverConfigVersion.cmake
  DESTINATION ${DROVER_PACKAGE_DIR} COMPONENT sdk)
