# Every scene in tests/data/scenes/ is bad input. Each must make `mfsi run` exit with code 2,
# write summary.json with status "error" and a message containing the text on the scene's
# "# expect:" line, and leave no steps.csv or field output behind.
include(${CMAKE_CURRENT_LIST_DIR}/support/summary.cmake)
file(REMOVE_RECURSE ${WORK})
file(GLOB scenes ${DATA}/scenes/*.yaml)
list(LENGTH scenes n)
if(n LESS 8)
  message(FATAL_ERROR "expected at least 8 bad scenes, found ${n}")
endif()
set(failures 0)
foreach(scene ${scenes})
  get_filename_component(name ${scene} NAME_WE)
  file(STRINGS ${scene} expect_line REGEX "^# expect: ")
  string(REPLACE "# expect: " "" expect "${expect_line}")
  set(out ${WORK}/${name})
  execute_process(COMMAND ${MFSI} run ${scene} --out ${out} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  if(NOT rc EQUAL 2)
    message(SEND_ERROR "${name}: exit code ${rc}, expected 2\n${o}\n${e}")
    math(EXPR failures "${failures}+1")
    continue()
  endif()
  mfsi_expect_summary(${out} error "${expect}" ${name})
  set(err "${summary_error}")
  string(FIND "${e}" "${expect}" pos2)
  if(pos2 EQUAL -1)
    message(SEND_ERROR "${name}: stderr lacks '${expect}': ${e}")
  endif()
  if(EXISTS ${out}/steps.csv OR EXISTS ${out}/fields)
    message(SEND_ERROR "${name}: partial output left behind")
  endif()
  message(STATUS "${name}: ok (${err})")
endforeach()

# A bad --set override is bad input too, and names the override.
execute_process(COMMAND ${MFSI} run ${CASES}/box.yaml --set mesh.blocks.0.cels=[2,2,2] --out ${WORK}/bad_set
  RESULT_VARIABLE rc ERROR_VARIABLE e OUTPUT_QUIET)
if(NOT rc EQUAL 2)
  message(SEND_ERROR "bad --set: exit code ${rc}, expected 2")
endif()
string(FIND "${e}" "cells" pos)
if(pos EQUAL -1)
  message(SEND_ERROR "bad --set: no suggestion of 'cells' in: ${e}")
endif()

# A scene that does not exist.
execute_process(COMMAND ${MFSI} run no_such_scene_anywhere --out ${WORK}/nosuch RESULT_VARIABLE rc ERROR_QUIET OUTPUT_QUIET)
if(NOT rc EQUAL 2)
  message(SEND_ERROR "missing scene: exit code ${rc}, expected 2")
endif()

# check validates without running.
execute_process(COMMAND ${MFSI} check ${DATA}/scenes/unknown_key.yaml RESULT_VARIABLE rc ERROR_QUIET OUTPUT_QUIET)
if(NOT rc EQUAL 2)
  message(SEND_ERROR "check of a bad scene: exit code ${rc}, expected 2")
endif()

# check refuses what run refuses, and an absurd mesh at once (nothing allocated); the README's
# one-block override of the two-block box names both blocks.
execute_process(COMMAND ${MFSI} check ${DATA}/scenes/huge_cells.yaml RESULT_VARIABLE rc ERROR_VARIABLE e OUTPUT_QUIET
  TIMEOUT 20)
string(FIND "${e}" "key 'mesh.blocks.0.cells'" pos)
if(NOT rc EQUAL 2 OR pos EQUAL -1)
  message(SEND_ERROR "check of 10^15 cells: exit ${rc}, expected 2 and the key mesh.blocks.0.cells: ${e}")
endif()
execute_process(COMMAND ${MFSI} check ${CASES}/box.yaml --set mesh.blocks.0.cells=[32,32,8]
  RESULT_VARIABLE rc ERROR_VARIABLE e OUTPUT_QUIET)
string(FIND "${e}" "mesh.blocks.0 face +x and mesh.blocks.1 face -x touch but their grids differ" pos)
if(NOT rc EQUAL 2 OR pos EQUAL -1)
  message(SEND_ERROR "check of mismatched blocks: exit ${rc}, expected 2 and both blocks named: ${e}")
endif()

# A scene that is not a regular file: a FIFO would block the reader forever, /dev/zero never ends.
execute_process(COMMAND mkfifo ${WORK}/scene.fifo RESULT_VARIABLE rc)
if(rc EQUAL 0)
  execute_process(COMMAND ${MFSI} check ${WORK}/scene.fifo RESULT_VARIABLE rc ERROR_VARIABLE e OUTPUT_QUIET TIMEOUT 20)
  string(FIND "${e}" "not a regular file" pos)
  if(NOT rc EQUAL 2 OR pos EQUAL -1)
    message(SEND_ERROR "FIFO as scene: exit ${rc}, expected 2 and 'not a regular file': ${e}")
  endif()
endif()
execute_process(COMMAND ${MFSI} check /dev/zero RESULT_VARIABLE rc ERROR_VARIABLE e OUTPUT_QUIET TIMEOUT 20)
if(NOT rc EQUAL 2)
  message(SEND_ERROR "/dev/zero as scene: exit ${rc}, expected 2: ${e}")
endif()

# Command-line errors are bad input (exit 2), not CLI11's own codes (105-114); --help is 0.
foreach(args "run --no-such-flag" "run --threads 0" "frobnicate")
  separate_arguments(argv UNIX_COMMAND "${args}")
  execute_process(COMMAND ${MFSI} ${argv} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT rc EQUAL 2)
    message(SEND_ERROR "mfsi ${args}: exit ${rc}, expected 2")
  endif()
endforeach()
execute_process(COMMAND ${MFSI} run --help RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
if(NOT rc EQUAL 0)
  message(SEND_ERROR "mfsi run --help: exit ${rc}, expected 0")
endif()
