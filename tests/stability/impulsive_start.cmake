# Impulsive start: the flexible-bottom cavity (12 x 12, 3 s) with the lid and the inflow at full
# speed from t = 0 (no 1 - cos ramp): the implicit coupling stays stable with and without the load
# filter (pNetFilterTau), the explicit scheme diverges (and, with checkpoints, leaves the last good one).
include(${CMAKE_CURRENT_LIST_DIR}/lib/Checks.cmake)
file(REMOVE_RECURSE ${WORK})
set(cavity flexible-cavity --set mesh.blocks.0.cells=[12,10,1] --set mesh.blocks.1.cells=[12,2,1] --set time.endTime=3
  --set fluid.boundary.lid.timeFunction.type=constant --set fluid.boundary.inlet.timeFunction.type=constant)
stable(impulsive 30 10 ${cavity})
stable(impulsive_filtered 30 10 ${cavity} --set coupling.pNetFilterTau=0.2)
diverges(impulsive_explicit 30 ${cavity} --set coupling.scheme=explicit)

# A run that diverges leaves its last good checkpoint and names it; a restart from there is a
# valid continuation (it reaches the same breakdown at the same step).
diverges(impulsive_explicit_saved 30 ${cavity} --set coupling.scheme=explicit --set output.checkpoint.everySteps=4)
file(READ ${WORK}/impulsive_explicit_saved/summary.json s)
string(JSON why GET "${s}" error)
string(JSON done GET "${s}" steps)
string(REGEX MATCH "last good checkpoint: ([^ ]+\\.h5)" found "${why}")
set(saved "${CMAKE_MATCH_1}")
math(EXPR expected "${done} / 4 * 4")
if(NOT found OR NOT EXISTS "${saved}" OR NOT saved MATCHES "checkpoint_0*${expected}\\.h5$")
  message(SEND_ERROR "the diverged run (${done} steps) names no last good checkpoint of step ${expected}: ${why}")
endif()
file(COPY ${WORK}/impulsive_explicit_saved/ DESTINATION ${WORK}/impulsive_explicit_again)
string(REPLACE "${WORK}/impulsive_explicit_saved" "${WORK}/impulsive_explicit_again" again "${saved}")
execute_process(COMMAND ${MFSI} run --restart ${again} --out ${WORK}/impulsive_explicit_again RESULT_VARIABLE rc
  OUTPUT_QUIET ERROR_QUIET)
file(READ ${WORK}/impulsive_explicit_again/summary.json s2)
string(JSON done2 GET "${s2}" steps)
string(JSON status2 GET "${s2}" status)
if(NOT rc EQUAL 3 OR NOT status2 STREQUAL "diverged" OR NOT done2 EQUAL done)
  message(SEND_ERROR "the restart from ${again}: exit ${rc}, ${status2} after ${done2} steps (the first run: ${done})")
endif()
message(STATUS "| impulsive_explicit_saved | diverged after ${done} steps, last good checkpoint of step ${expected}; the restart from it diverges after ${done2} |")
