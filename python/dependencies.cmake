# Finds what the Python module needs (python/CMakeLists.txt, docs/python.md) without failing:
# sets DUALGRID_PYTHON_DEPS_FOUND, the default of the top-level option DUALGRID_BUILD_PYTHON.
#
# The interpreter: -DPython3_EXECUTABLE=... if given; otherwise the first of `python3` on PATH and
# /usr/bin/python3 that imports numpy. Why not FindPython's first pick alone: a pyenv or venv
# python3 ahead of Debian's on PATH often lacks numpy, and the module (and its tests) must run
# under an interpreter that has it; /usr/bin/python3 is also the one whose dist-packages
# `cmake --install` targets.
set(DUALGRID_PYTHON_DEPS_FOUND OFF)
set(numpy_status "not checked")
if(NOT Python3_EXECUTABLE)
  find_program(DUALGRID_PATH_PYTHON3 NAMES python3)
  foreach(candidate ${DUALGRID_PATH_PYTHON3} /usr/bin/python3)
    if(EXISTS "${candidate}")
      execute_process(COMMAND "${candidate}" -c "import numpy" RESULT_VARIABLE numpy_rc
                      OUTPUT_QUIET ERROR_QUIET)
      if(numpy_rc EQUAL 0)
        set(Python3_EXECUTABLE "${candidate}" CACHE FILEPATH "Python interpreter of the module")
        break()
      endif()
    endif()
  endforeach()
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module QUIET)
if(Python3_FOUND)
  execute_process(COMMAND "${Python3_EXECUTABLE}" -c "import numpy" RESULT_VARIABLE numpy_rc
                  OUTPUT_QUIET ERROR_QUIET)
  if(numpy_rc EQUAL 0)
    set(numpy_status "yes")
  else()
    set(numpy_status "no")
  endif()
  # After Python3: pybind11's config then uses FindPython's results (its "new" mode).
  find_package(pybind11 CONFIG QUIET)
  if(pybind11_FOUND AND numpy_rc EQUAL 0)
    set(DUALGRID_PYTHON_DEPS_FOUND ON)
  endif()
endif()
if(NOT DUALGRID_PYTHON_DEPS_FOUND)
  message(STATUS "Python module: needs Python3 (Interpreter, Development.Module), pybind11 and "
                 "numpy (Debian: python3-dev pybind11-dev python3-numpy); "
                 "Python3 found: ${Python3_FOUND} (${Python3_EXECUTABLE}), "
                 "numpy importable: ${numpy_status}, pybind11 found: ${pybind11_FOUND}")
endif()
