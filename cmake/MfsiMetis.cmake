# METIS (Debian's libmetis-dev): the cell decomposition for distributed runs. Only core's sources
# include metis.h, so core takes the include folder privately and exports the library path (a
# downstream find_package(mfsi) needs no METIS search of its own), as with HDF5.
find_path(METIS_INCLUDE_DIR metis.h REQUIRED)
find_library(METIS_LIBRARY metis REQUIRED)
message(STATUS "METIS: ${METIS_LIBRARY}")
