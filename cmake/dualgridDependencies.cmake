# The third-party packages that dualgrid's libraries link, found the same way by this project's
# build and by a consumer's find_package(dualgrid) (installed beside dualgridConfig.cmake).
# All are Debian packages (scripts/bootstrap.sh names them).
# REQUIRED: a missing package stops with CMake's own message naming it.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(hwy REQUIRED)  # Highway (libhwy-dev): the filter's and the radar scan's SIMD
find_package(yaml-cpp REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
# libsumo: SUMO's CMake config ships in Debian's sumo-tools; without it, find the headers and the
# library of the sumo package directly. SUMO_HOME (netconvert's schemas) is /usr/share/sumo.
if(NOT TARGET SUMO::libsumocpp)
  find_package(SUMO CONFIG QUIET PATHS /usr/share/sumo/cmake)
endif()
if(NOT TARGET SUMO::libsumocpp)
  find_path(LIBSUMO_INCLUDE_DIR libsumo/libsumo.h)
  find_library(LIBSUMO_LIBRARY sumocpp)
  if(NOT LIBSUMO_INCLUDE_DIR OR NOT LIBSUMO_LIBRARY)
    message(FATAL_ERROR "libsumo not found (libsumo/libsumo.h and libsumocpp): install the Debian "
                        "package 'sumo' (apt-get install sumo sumo-tools)")
  endif()
  add_library(SUMO::libsumocpp SHARED IMPORTED GLOBAL)
  set_target_properties(SUMO::libsumocpp PROPERTIES IMPORTED_LOCATION ${LIBSUMO_LIBRARY}
                        INTERFACE_INCLUDE_DIRECTORIES ${LIBSUMO_INCLUDE_DIR})
  message(STATUS "SUMO's CMake config not found (package sumo-tools); using ${LIBSUMO_LIBRARY}")
endif()
find_package(ZLIB REQUIRED)
find_package(PNG REQUIRED)  # viz: the figures' PNG files (libpng-dev)
find_package(Threads REQUIRED)  # outputs: the replay writer's worker thread
find_package(EXPAT REQUIRED)  # users' SUMO files, parsed streaming (sim/xml_scan.hpp)
find_package(PkgConfig REQUIRED)
if(NOT TARGET PkgConfig::CAIRO)
  pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET GLOBAL cairo)
endif()
# Recorded data (dualgrid::recorded): RadarScenes' HDF5 files through the C library of Debian's
# libhdf5-dev, by its pkg-config file (CMake's FindHDF5 needs the C language enabled, which
# neither this project nor a C++ consumer has).
if(NOT TARGET PkgConfig::HDF5)
  pkg_check_modules(HDF5 REQUIRED IMPORTED_TARGET GLOBAL hdf5)
endif()
find_path(RANDOM123_INCLUDE_DIR Random123/philox.h)
if(NOT RANDOM123_INCLUDE_DIR)
  message(FATAL_ERROR "Random123 not found (Random123/philox.h): install the Debian package "
                      "'librandom123-dev'")
endif()
