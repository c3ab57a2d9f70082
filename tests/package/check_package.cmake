# Install membrane-fsi into a scratch prefix, build a downstream project against it with
# find_package(mfsi), run it. Arguments: BUILD (our build dir), SRC (this folder), WORK, KOKKOS_DIR,
# CXX_FLAGS and LINKER_FLAGS (our build's own, e.g. the sanitizers of build-variant.sh asan, which
# the consumer must link with too).
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${WORK}/prefix RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "install failed")
endif()
file(MAKE_DIRECTORY ${WORK}/src)
configure_file(${SRC}/CMakeLists.txt.in ${WORK}/src/CMakeLists.txt COPYONLY)
configure_file(${SRC}/consumer.cpp ${WORK}/src/consumer.cpp COPYONLY)
execute_process(COMMAND ${CMAKE_COMMAND} -S ${WORK}/src -B ${WORK}/build -DCMAKE_BUILD_TYPE=Release
  "-DCMAKE_PREFIX_PATH=${WORK}/prefix" -DKokkos_DIR=${KOKKOS_DIR} "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}"
  "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}" RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configure of the consumer failed:\n${o}\n${e}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK}/build RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "build of the consumer failed:\n${o}\n${e}")
endif()
execute_process(COMMAND ${WORK}/build/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE o)
string(STRIP "${o}" o)
if(NOT rc EQUAL 0 OR NOT o STREQUAL "27")
  message(FATAL_ERROR "consumer printed '${o}' (exit ${rc}); expected 27 cells")
endif()
