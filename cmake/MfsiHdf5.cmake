# HDF5 of the MPI build (Debian's libhdf5-openmpi-dev): field output and checkpoints. Only core's
# sources include hdf5.h, so core takes the include folders privately and exports the library paths
# (a downstream find_package(mfsi) needs no HDF5 search of its own). FindHDF5 compiles a C probe.
enable_language(C)
set(HDF5_PREFER_PARALLEL TRUE)
find_package(HDF5 REQUIRED COMPONENTS C)
if(NOT HDF5_IS_PARALLEL)
  message(STATUS "HDF5 ${HDF5_VERSION} is a serial build: field output works on one rank")
endif()
