# `cpack -G DEB` in the build directory: tetra_VERSION_amd64.deb (the program, man pages, completion, IDL,
# DDS configuration, examples), tetra-dev_VERSION_amd64.deb (libraries, headers, CMake and pkg-config
# files) and, with the Python package built, python3-tetra_VERSION_amd64.deb (the Python package, docs/python.md).
# Configure with -DCMAKE_INSTALL_PREFIX=/usr for Debian's paths (docs/install.md).
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
if(TETRA_BUILD_PYTHON)
  list(APPEND CPACK_COMPONENTS_ALL python)
endif()
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME tetra)
set(CPACK_DEBIAN_DEV_PACKAGE_NAME tetra-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
if(TETRA_BUILD_PYTHON)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-tetra)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
  # The module links the libraries statically; it needs Python and numpy, pandas for its frames.
  set(CPACK_DEBIAN_PYTHON_PACKAGE_SHLIBDEPS ON)
  # The module is built for one Python minor version (its ABI): the package asks for that one.
  math(EXPR TETRA_PYTHON_NEXT_MINOR "${Python3_VERSION_MINOR} + 1")
  set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "python3 (>= ${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}), \
python3 (<< ${Python3_VERSION_MAJOR}.${TETRA_PYTHON_NEXT_MINOR}), python3-numpy")
  set(CPACK_DEBIAN_PYTHON_PACKAGE_RECOMMENDS "python3-pandas, python3-matplotlib")
endif()
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
set(CPACK_DEBIAN_PYTHON_DESCRIPTION "The Python package tetra: calibration, Allan analysis, simulation, the fusion and fault-detection
pipeline, scoring and fault-injection campaigns from Python, with numpy arrays and pandas frames.")
include(CPack)
