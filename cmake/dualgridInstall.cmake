# dualgrid_install_library(TARGET EXPORT_NAME) makes one of dualgrid's libraries installable:
# position-independent (the Python module links the static libraries), exported as
# dualgrid::EXPORT_NAME, and its public headers (the folder's include/) installed. The headers
# need C++20 (std::span, designated initialisers): the requirement is part of the target, so a
# consumer gets it without setting a standard.
include(GNUInstallDirs)
function(dualgrid_install_library target export_name)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON
                                             EXPORT_NAME ${export_name})
  install(TARGETS ${target} EXPORT dualgridTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/include)
    install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  endif()
endfunction()
# Where the installed tree keeps its data; sim::FindDataDir looks for them beside the program.
set(DUALGRID_INSTALL_NETWORK_DIR ${CMAKE_INSTALL_DATADIR}/dualgrid/networks)
set(DUALGRID_INSTALL_SCENARIO_DIR ${CMAKE_INSTALL_DATADIR}/dualgrid/scenarios)
