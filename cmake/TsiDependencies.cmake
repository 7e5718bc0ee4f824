# Every dependency is a Debian package (see README.md, "Dependencies").
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Boost 1.74 REQUIRED)          # header-only: Boost.Odeint
find_package(PkgConfig REQUIRED)
# FFTW in the build's precision (TSI_PRECISION): libfftw3 or libfftw3l, both in libfftw3-dev.
if(TSI_PRECISION STREQUAL "long-double")
  pkg_check_modules(FFTW3 REQUIRED IMPORTED_TARGET fftw3l)
  set(TSI_FFTW_THREADS_NAME fftw3l_threads)
elseif(TSI_PRECISION STREQUAL "quad")
  pkg_check_modules(FFTW3 REQUIRED IMPORTED_TARGET fftw3q)
  set(TSI_FFTW_THREADS_NAME fftw3q_threads)
else()
  pkg_check_modules(FFTW3 REQUIRED IMPORTED_TARGET fftw3)
  set(TSI_FFTW_THREADS_NAME fftw3_threads)
endif()
# FFTW's thread support (libfftw3_threads, in the same Debian package) has no .pc file of its own.
find_library(FFTW3_THREADS_LIBRARY NAMES ${TSI_FFTW_THREADS_NAME} HINTS ${FFTW3_LIBRARY_DIRS} REQUIRED)
find_package(Threads REQUIRED)

# OpenMP (optional: GCC's libgomp; clang needs libomp-dev): one two-scale run splits a large
# tau grid over threads (tsi --threads, core/include/tsi/tau_grid_threads.hpp). Without it a
# run uses one thread and everything else is unchanged.
find_package(OpenMP COMPONENTS CXX QUIET)
option(TSI_WITH_OPENMP "Split one run's tau grid over threads (tsi --threads)" ${OpenMP_CXX_FOUND})
if(TSI_WITH_OPENMP AND NOT OpenMP_CXX_FOUND)
  message(FATAL_ERROR "TSI_WITH_OPENMP is ON but no OpenMP was found (GCC has it; clang: apt-get install libomp-dev)")
endif()
message(STATUS "tsi: threads on the tau grid (OpenMP) ${TSI_WITH_OPENMP}")

# MPI (optional: Debian's libopenmpi-dev): `mpirun -np N tsi study` spreads a study's runs over
# ranks (apps/tsi/study_mpi.cpp). Without it tsi builds as before; --shard/--merge need no MPI.
find_package(MPI COMPONENTS CXX QUIET)
option(TSI_WITH_MPI "Distribute studies over MPI ranks (mpirun -np N tsi study)" ${MPI_CXX_FOUND})
if(TSI_WITH_MPI AND NOT MPI_CXX_FOUND)
  message(FATAL_ERROR "TSI_WITH_MPI is ON but no MPI was found (Debian: apt-get install libopenmpi-dev openmpi-bin)")
endif()
message(STATUS "tsi: MPI studies ${TSI_WITH_MPI}")
# HDF5 (optional: Debian's libhdf5-dev, serial): output.fields_every writes a grid model's fields
# as HDF5 with an XDMF sidecar for ParaView (apps/tsi/field_snapshots.cpp), through a module that
# only such runs load (apps/tsi/hdf5_fields). A split run's ranks write their rows of a large
# snapshot in turn. Without HDF5, output.fields_every is refused.
pkg_check_modules(HDF5 QUIET IMPORTED_TARGET hdf5)
option(TSI_WITH_HDF5 "Write field snapshots in HDF5 + XDMF (output.fields_every)" ${HDF5_FOUND})
if(TSI_WITH_HDF5 AND NOT HDF5_FOUND)
  message(FATAL_ERROR "TSI_WITH_HDF5 is ON but no HDF5 was found (Debian: apt-get install libhdf5-dev)")
endif()
message(STATUS "tsi: HDF5 field snapshots ${TSI_WITH_HDF5}")

# FFTW's MPI transforms (Debian's libfftw3-mpi-dev: libfftw3_mpi, libfftw3l_mpi), with MPI: a
# split run's spectral grid in slabs over the ranks (tsi run --split; apps/tsi/split_processes.cpp).
if(TSI_WITH_MPI AND NOT TSI_PRECISION STREQUAL "quad")  # a quad build never splits
  if(TSI_PRECISION STREQUAL "long-double")
    set(TSI_FFTW_MPI_NAME fftw3l_mpi)
  else()
    set(TSI_FFTW_MPI_NAME fftw3_mpi)
  endif()
  find_library(TSI_FFTW_MPI_LIBRARY NAMES ${TSI_FFTW_MPI_NAME} HINTS ${FFTW3_LIBRARY_DIRS})
  if(NOT TSI_FFTW_MPI_LIBRARY)
    message(FATAL_ERROR "TSI_WITH_MPI is ON but FFTW's MPI library (${TSI_FFTW_MPI_NAME}) was not found (Debian: "
                        "apt-get install libfftw3-mpi-dev)")
  endif()
endif()
