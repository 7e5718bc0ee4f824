# Every dependency is a Debian package (see README.md, "Dependencies").
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Boost 1.74 REQUIRED)          # header-only: Boost.Odeint
find_package(PkgConfig REQUIRED)
pkg_check_modules(FFTW3 REQUIRED IMPORTED_TARGET fftw3)
# FFTW's thread support (libfftw3_threads, in the same Debian package) has no .pc file of its own.
find_library(FFTW3_THREADS_LIBRARY NAMES fftw3_threads HINTS ${FFTW3_LIBRARY_DIRS} REQUIRED)
find_package(Threads REQUIRED)

# MPI (optional: Debian's libopenmpi-dev): `mpirun -np N tsi study` spreads a study's runs over
# ranks (apps/tsi/study_mpi.cpp). Without it tsi builds as before; --shard/--merge need no MPI.
find_package(MPI COMPONENTS CXX QUIET)
option(TSI_WITH_MPI "Distribute studies over MPI ranks (mpirun -np N tsi study)" ${MPI_CXX_FOUND})
if(TSI_WITH_MPI AND NOT MPI_CXX_FOUND)
  message(FATAL_ERROR "TSI_WITH_MPI is ON but no MPI was found (Debian: apt-get install libopenmpi-dev openmpi-bin)")
endif()
message(STATUS "tsi: MPI studies ${TSI_WITH_MPI}")
