# Helpers shared by every layer's CMakeLists.

# Warnings as errors on our own code only (never on Kokkos, Eigen, yaml-cpp ... headers).
function(mfsi_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(MFSI_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# mfsi_library(NAME <layer> DEPS <targets...>)
# One static library per layer, made of every .cpp in the folder (CONFIGURE_DEPENDS, so a new
# file needs no CMake edit). A layer with no sources yet is a header-only INTERFACE library.
function(mfsi_library)
  cmake_parse_arguments(L "" "NAME" "DEPS" ${ARGN})
  file(GLOB_RECURSE srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  set(target mfsi_${L_NAME})
  if(srcs)
    add_library(${target} STATIC ${srcs})
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
