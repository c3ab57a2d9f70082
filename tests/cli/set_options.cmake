# Each --set takes exactly one value and may be repeated, before or after the scene: a --set in
# front of the scene's name does not swallow it (issue 14). A --set without a value is a
# command-line error: exit 2 like any other bad input.
include(${CMAKE_CURRENT_LIST_DIR}/support/summary.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

# check: the scene after one --set, after two, and before them; --set=value too.
foreach(args "--set time.endTime=1 cavity"
             "--set time.endTime=1 --set mesh.blocks.0.cells=[4,4,1] cavity"
             "cavity --set time.endTime=1 --set mesh.blocks.0.cells=[4,4,1]"
             "--set=mesh.blocks.0.cells=[4,4,1] cavity")
  separate_arguments(argv UNIX_COMMAND "${args}")
  execute_process(COMMAND ${MFSI} check ${argv} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  string(FIND "${o}" "cavity.yaml: scene 'cavity'" pos)
  if(NOT rc EQUAL 0 OR pos EQUAL -1)
    message(SEND_ERROR "mfsi check ${args}: exit ${rc}, expected 0 and the cavity scene:\n${o}\n${e}")
  endif()
  string(FIND "${args}" "[4,4,1]" small)
  string(FIND "${o}" " 16 cells" pos)
  if(NOT small EQUAL -1 AND pos EQUAL -1)
    message(SEND_ERROR "mfsi check ${args}: the override of the cells did not apply:\n${o}")
  endif()
endforeach()

# run: both overrides apply to the scene named after them (one step of a 4 x 4 cavity).
execute_process(COMMAND ${MFSI} run --set time.endTime=1 --set mesh.blocks.0.cells=[4,4,1] cavity
  --out ${WORK}/run RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mfsi run --set ... cavity: exit ${rc}, expected 0\n${o}\n${e}")
endif()
mfsi_expect_summary(${WORK}/run ok "" "mfsi run --set ... cavity")
file(READ ${WORK}/run/summary.json js)
string(JSON scene GET "${js}" scene)
string(JSON cells GET "${js}" cells)
if(NOT scene STREQUAL "cavity" OR NOT summary_steps EQUAL 1 OR NOT cells EQUAL 16)
  message(SEND_ERROR "mfsi run --set ... cavity: scene '${scene}', ${summary_steps} step(s), ${cells} cells; "
    "expected 'cavity', 1 step, 16 cells")
endif()

# Command-line errors: a --set without a value (at the end, or before another option), two values
# for one --set where no scene is expected (check takes one scene).
foreach(args "check --set" "check cavity --set" "run --set --out ${WORK}/bad cavity" "check --set a.b=1 cavity extra")
  separate_arguments(argv UNIX_COMMAND "${args}")
  execute_process(COMMAND ${MFSI} ${argv} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
  if(NOT rc EQUAL 2)
    message(SEND_ERROR "mfsi ${args}: exit ${rc}, expected 2 (a command-line error)\n${e}")
  endif()
endforeach()
if(EXISTS ${WORK}/bad)
  message(SEND_ERROR "mfsi run --set --out ...: a command-line error wrote into the output folder")
endif()
