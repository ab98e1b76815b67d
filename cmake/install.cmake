# Install rules (docs/install.md): `cmake --install build [--prefix DIR]`, and the .deb of cmake/package.cmake.
# Two components: `runtime` (the program, man pages, completion, IDL, DDS configuration, examples) and `dev`
# (libraries, headers, CMake package tetra::core/fdi/sim, pkg-config file).
include(CMakePackageConfigHelpers)

set(TETRA_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/tetra)

# --- runtime ----------------------------------------------------------------------------------
install(TARGETS tetra RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/idl/tetra.idl ${PROJECT_SOURCE_DIR}/idl/ros2.idl
        DESTINATION ${CMAKE_INSTALL_DATADIR}/tetra/idl COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/config/cyclonedds-loopback.xml
        DESTINATION ${CMAKE_INSTALL_DATADIR}/tetra COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples COMPONENT runtime)
# The ground station's web application (tetra ground finds it at ../share/tetra/web beside the program),
# with Open MCT's built files when `npm ci` has been run in web/ (otherwise tetra ground says so).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/web/ DESTINATION ${CMAKE_INSTALL_DATADIR}/tetra/web COMPONENT runtime
        PATTERN node_modules EXCLUDE)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/web/node_modules/openmct/dist/
        DESTINATION ${CMAKE_INSTALL_DATADIR}/tetra/web/node_modules/openmct/dist COMPONENT runtime OPTIONAL)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/bash-completion/tetra
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions COMPONENT runtime)

# Man pages: one per command, from the --help texts, built with the program (cmake/man_pages.sh).
find_program(TETRA_HELP2MAN help2man)
if(TETRA_HELP2MAN)
  set(TETRA_MAN_DIR ${PROJECT_BINARY_DIR}/man)
  add_custom_command(OUTPUT ${TETRA_MAN_DIR}/stamp
    COMMAND bash ${PROJECT_SOURCE_DIR}/cmake/man_pages.sh $<TARGET_FILE:tetra> ${PROJECT_VERSION} ${TETRA_MAN_DIR}
    DEPENDS tetra ${PROJECT_SOURCE_DIR}/cmake/man_pages.sh
    COMMENT "Man pages from the --help texts (help2man)")
  add_custom_target(tetra_man ALL DEPENDS ${TETRA_MAN_DIR}/stamp)
  install(DIRECTORY ${TETRA_MAN_DIR}/ DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT runtime
          FILES_MATCHING PATTERN "*.1.gz" PATTERN wrappers EXCLUDE)
else()
  message(STATUS "help2man not found: no man pages (scripts/setup.sh installs it)")
endif()

# --- dev: libraries, headers, CMake package, pkg-config -----------------------------------------
install(TARGETS tetra_core tetra_fdi tetra_sim EXPORT tetraTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(lib core fdi sim)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${lib}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev)
endforeach()
install(EXPORT tetraTargets NAMESPACE tetra:: DESTINATION ${TETRA_CMAKE_DIR} COMPONENT dev)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/tetraConfig.cmake.in
  ${PROJECT_BINARY_DIR}/tetraConfig.cmake INSTALL_DESTINATION ${TETRA_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/tetraConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)  # 0.x: a minor release may change the API
install(FILES ${PROJECT_BINARY_DIR}/tetraConfig.cmake ${PROJECT_BINARY_DIR}/tetraConfigVersion.cmake
        DESTINATION ${TETRA_CMAKE_DIR} COMPONENT dev)
# The pkg-config file finds its prefix from its own place (${pcfiledir}): right under any --prefix or DESTDIR.
file(RELATIVE_PATH TETRA_PC_TO_PREFIX /p/${CMAKE_INSTALL_LIBDIR}/pkgconfig /p)
string(REGEX REPLACE "/$" "" TETRA_PC_TO_PREFIX "${TETRA_PC_TO_PREFIX}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/tetra.pc.in ${PROJECT_BINARY_DIR}/tetra.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/tetra.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT dev)
