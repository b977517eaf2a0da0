# Installs the parts of Drover that other projects build against, with an exported CMake
# package: an out-of-tree project (a vehicle integrator's RAN) does
#   find_package(drover REQUIRED)
#   target_link_libraries(my_ran PRIVATE drover::ran)
# Included from the end of the top CMakeLists.txt, after every target exists. Everything here
# is in the install component "sdk" (`cmake --install build --component sdk` installs only it).

include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(DROVER_PACKAGE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/drover)

# The exported targets and what they need. Exported as drover::<name>: drover::ran (the SDK,
# no DDS) and drover::ran_runner (runs a driver on DDS) with drover::common,
# drover::topology, drover::types (the generated IDL types) and drover::dds beneath them.
set(_drover_exported drover_common drover_topology drover_ran drover_types drover_dds
  drover_ran_runner)
foreach(_target IN LISTS _drover_exported)
  string(REPLACE "drover_" "" _name ${_target})
  set_target_properties(${_target} PROPERTIES EXPORT_NAME ${_name})
endforeach()

# Inside the build these come from the top CMakeLists (add_compile_definitions); users of
# the installed package need them too, as the public headers include Boost.Geometry.
target_compile_definitions(drover_topology INTERFACE
  $<INSTALL_INTERFACE:BOOST_ALLOW_DEPRECATED_HEADERS BOOST_BIND_GLOBAL_PLACEHOLDERS>)

# The DDS layer's and the generated types' headers are found in the build tree only
# (BUILD_INTERFACE in their CMakeLists); installed, they live under include/.
target_include_directories(drover_dds PUBLIC $<INSTALL_INTERFACE:include>)
target_include_directories(drover_types SYSTEM PUBLIC $<INSTALL_INTERFACE:include/drover/msg>)

install(TARGETS ${_drover_exported} EXPORT droverTargets COMPONENT sdk
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY
    ${PROJECT_SOURCE_DIR}/common/include/
    ${PROJECT_SOURCE_DIR}/topology/include/
    ${PROJECT_SOURCE_DIR}/ran/include/
    ${PROJECT_SOURCE_DIR}/agents/dds/include/
    ${PROJECT_SOURCE_DIR}/agents/ran_runner/include/
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT sdk)
# fastddsgen's output (and any hand-written header beside the IDL files).
install(DIRECTORY ${PROJECT_BINARY_DIR}/idl/generated/ ${PROJECT_SOURCE_DIR}/idl/
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/drover/msg COMPONENT sdk
  FILES_MATCHING PATTERN "*.h")

install(EXPORT droverTargets NAMESPACE drover:: DESTINATION ${DROVER_PACKAGE_DIR} COMPONENT sdk)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/droverConfig.cmake.in
  ${PROJECT_BINARY_DIR}/droverConfig.cmake
  INSTALL_DESTINATION ${DROVER_PACKAGE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/droverConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/droverConfig.cmake ${PROJECT_BINARY_DIR}/droverConfigVersion.cmake
  DESTINATION ${DROVER_PACKAGE_DIR} COMPONENT sdk)
