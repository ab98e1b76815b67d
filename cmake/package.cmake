# `cpack -G DEB` in the build directory: tetra_VERSION_amd64.deb (the program, man pages, completion, IDL,
# DDS configuration, examples) and tetra-dev_VERSION_amd64.deb (libraries, headers, CMake and pkg-config
# files). Configure with -DCMAKE_INSTALL_PREFIX=/usr for Debian's paths (docs/install.md).
set(CPACK_PACKAGE_NAME tetra)
set(CPACK_PACKAGE_VENDOR "tetra")
set(CPACK_PACKAGE_CONTACT "tetra maintainers <tetra@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "calibration, Allan variance, simulation and fault-tolerant fusion for redundant gyro packages")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX ${CMAKE_INSTALL_PREFIX})
set(CPACK_GENERATOR DEB)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME tetra)
set(CPACK_DEBIAN_DEV_PACKAGE_NAME tetra-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
# The program's shared-library dependencies (Cyclone DDS, yaml-cpp, spdlog, fmt, libstdc++) from dpkg-shlibdeps.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS "gnuplot-nox")  # tetra allan --plot
# Headers and static libraries: what tetraConfig.cmake and tetra.pc ask for.
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "libeigen3-dev (>= 3.3), libyaml-cpp-dev, libhdf5-dev, pkg-config")
# Extended descriptions (the synopsis of both is CPACK_PACKAGE_DESCRIPTION_SUMMARY).
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION "The tetra program: turntable calibration, Allan deviation, simulation with faults, the fusion and
fault-detection pipeline, and its DDS service and ground tools (Eclipse Cyclone DDS).")
set(CPACK_DEBIAN_DEV_DESCRIPTION "The C++20 libraries tetra::core, tetra::fdi and tetra::sim: static libraries, headers, the CMake package (find_package(tetra)) and the pkg-config file (tetra.pc)
of tetra's calibration, Allan analysis, fusion pipeline and simulator.")
include(CPack)
