# The Python package (python/): built when Debian's python3-dev and pybind11-dev are there,
# for the system interpreter (/usr/bin/python3, which has python3-numpy) unless
# Python3_EXECUTABLE names another. Sets TSI_PYTHON_BUILT and, when numpy imports,
# TSI_PYTHON_HAS_NUMPY (the Python tests need it).
set(TSI_PYTHON_BUILT OFF)
set(TSI_PYTHON_HAS_NUMPY OFF)
if(NOT Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "the Python the package tsi is built for")
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module)
if(Python3_FOUND)
  find_package(pybind11 2.6 CONFIG QUIET)
endif()
if(Python3_FOUND AND pybind11_FOUND)
  add_subdirectory(python)
  set(TSI_PYTHON_BUILT ON)
  execute_process(COMMAND ${Python3_EXECUTABLE} -c "import numpy" RESULT_VARIABLE tsi_numpy_rc
                  OUTPUT_QUIET ERROR_QUIET)
  if(tsi_numpy_rc EQUAL 0)
    set(TSI_PYTHON_HAS_NUMPY ON)
  else()
    message(STATUS "tsi: numpy does not import in ${Python3_EXECUTABLE}: the Python tests are left out "
                   "(install python3-numpy)")
  endif()
else()
  message(STATUS "tsi: the Python package is not built (install python3-dev and pybind11-dev)")
endif()
