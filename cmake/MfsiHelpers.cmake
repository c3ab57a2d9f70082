# Helpers shared by every layer's CMakeLists.

# Warnings as errors on our own code only (never on Kokkos, Eigen, yaml-cpp ... headers).
function(mfsi_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(MFSI_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# mfsi_library(NAME <layer> DEPS <targets...> [OWN_UNIT <sources...>])
# One static library per layer, made of every .cpp in the folder (CONFIGURE_DEPENDS, so a new
# file needs no CMake edit). A layer with no sources yet is a header-only INTERFACE library.
# OWN_UNIT: sources a unity build (CMAKE_UNITY_BUILD, the CUDA build of scripts/build-variant.sh)
# compiles on their own, not batched with the others: those whose file-scope names (a using-
# directive, a helper in an anonymous namespace) would clash with or leak into another source.
function(mfsi_library)
  cmake_parse_arguments(L "" "NAME" "DEPS;OWN_UNIT" ${ARGN})
  file(GLOB_RECURSE srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  set(target mfsi_${L_NAME})
  if(srcs)
    add_library(${target} STATIC ${srcs})
    if(L_OWN_UNIT)
      set_source_files_properties(${L_OWN_UNIT} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
    endif()
    target_include_directories(${target} PUBLIC
      $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/mfsi>)
    target_link_libraries(${target} PUBLIC ${L_DEPS})
    mfsi_warnings(${target})
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE
      $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/mfsi>)
    target_link_libraries(${target} INTERFACE ${L_DEPS})
  endif()
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${L_NAME})
  add_library(mfsi::${L_NAME} ALIAS ${target})
  install(TARGETS ${target} EXPORT mfsiTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/mfsi/${L_NAME}
    FILES_MATCHING PATTERN "*.hpp")
endfunction()

# mfsi_builds_executable(<source> <out-var>)
# Whether the test or benchmark of <source> is built: always, but under MFSI_KERNEL_TARGETS_ONLY
# (the compile-only device build) only when <source>, or a "support/..." header it includes from
# its own tree, writes a Kokkos kernel (a parallel dispatch or a device-annotated function): a
# host-only test compiled by nvcc checks nothing that the main build and the libraries' device
# compile do not.
function(mfsi_builds_executable src out)
  if(NOT MFSI_KERNEL_TARGETS_ONLY)
    set(${out} TRUE PARENT_SCOPE)
    return()
  endif()
  set(kernel_re "KOKKOS_LAMBDA|KOKKOS_CLASS_LAMBDA|KOKKOS_INLINE_FUNCTION|KOKKOS_FUNCTION|parallel_for|parallel_reduce|parallel_scan")
  file(READ ${src} text)
  set(found FALSE)
  if(text MATCHES "${kernel_re}")
    set(found TRUE)
  else()
    get_filename_component(dir ${src} DIRECTORY)
    get_filename_component(root ${dir} DIRECTORY)
    string(REGEX MATCHALL "#include \"support/[A-Za-z0-9_]+\\.hpp\"" incs "${text}")
    foreach(inc ${incs})
      string(REGEX REPLACE "#include \"(support/[A-Za-z0-9_]+\\.hpp)\"" "\\1" rel "${inc}")
      foreach(base ${dir} ${root})
        if(EXISTS ${base}/${rel})
          file(READ ${base}/${rel} htext)
          if(htext MATCHES "${kernel_re}")
            set(found TRUE)
          endif()
        endif()
      endforeach()
    endforeach()
  endif()
  set(${out} ${found} PARENT_SCOPE)
endfunction()

# mfsi_build_speed_options()
# MFSI_PCH (default on, off for device builds and for compilers other than GCC and Clang): the
# tests precompile the third-party headers nearly every test source parses (MFSI_PCH_HEADERS:
# Kokkos, Eigen, MPI, the standard library, and GoogleTest) once, and every test executable reuses
# them (tests/CMakeLists.txt): the test sources of the Release build 409 s -> 350 s on 2 cores.
# The libraries do not: their sources are smaller, and a small one that does not need Kokkos
# compiles slower with it (measured: core/Suggest.cpp 0.6 -> 1.5 s, the largest about 1 s faster).
# -Winvalid-pch, an error with MFSI_WERROR, turns a precompiled header that a target cannot use
# into a build error, not a silent slow-down. nvcc cannot read a host compiler's precompiled header.
# Then mfsi_use_fast_linker().
macro(mfsi_build_speed_options)
  set(_mfsi_pch_default ON)
  if(Kokkos_DEVICES MATCHES "CUDA|HIP|SYCL|OPENMPTARGET" OR NOT CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    set(_mfsi_pch_default OFF)
  endif()
  option(MFSI_PCH "Precompile the third-party headers of the test sources once" ${_mfsi_pch_default})
  set(MFSI_PCH_HEADERS <Kokkos_Core.hpp> <Eigen/Dense> <mpi.h> <gtest/gtest.h> <algorithm> <array> <cmath>
      <cstdio> <filesystem> <fstream> <functional> <map> <memory> <sstream> <string> <vector>)
  mfsi_use_fast_linker()
endmacro()

# mfsi_use_fast_linker()
# Links with lld, else gold, where the compiler can use one (MFSI_FAST_LINKER, default on; off for
# device builds, whose compiler wrappers pass link options on their own terms): a test executable
# links in 0.3 s against GNU ld's 1.0 s, and a build links about a hundred of them.
function(mfsi_use_fast_linker)
  set(default ON)
  if(Kokkos_DEVICES MATCHES "CUDA|HIP|SYCL|OPENMPTARGET")
    set(default OFF)
  endif()
  option(MFSI_FAST_LINKER "Link with lld or gold where available" ${default})
  if(NOT MFSI_FAST_LINKER)
    return()
  endif()
  include(CheckCXXSourceCompiles)
  foreach(ld lld gold)
    set(CMAKE_REQUIRED_LINK_OPTIONS -fuse-ld=${ld})
    set(CMAKE_REQUIRED_QUIET ON)
    check_cxx_source_compiles("int main() { return 0; }" MFSI_LINKER_${ld})
    if(MFSI_LINKER_${ld})
      add_link_options(-fuse-ld=${ld})
      message(STATUS "mfsi: linking with ${ld}")
      return()
    endif()
  endforeach()
endfunction()
