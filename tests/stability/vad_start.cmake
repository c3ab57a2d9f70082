# The pulsatile VAD's first 40 ms (cases/vad.yaml on the blood chamber's mesh
# cases/meshes/vad_blood.msh, which scripts/vad_mesh.py --blood-only writes byte for byte: checked
# here where numpy is installed): the air chamber, lumped behind the membrane, fills at the
# ejection pulse's rate and pushes the domed membrane (plate bending, tension field with a residual
# stiffness) into the blood, which leaves through the open outlet's resistance. Every step's
# coupling converges (measured 3.95 iterations per step, 10 at most; asserted at most 12), the mesh
# keeps its starting quality, and the air chamber's pressure climbs from p0 = 65 mmHg to the
# outlet's working range: above the outlet's p0 + C_r q = 88 mmHg at t = 0.04 s (q = 169 cm^3/s)
# by what drives the blood through the chamber (measured 98.7 mmHg; asserted 90-110). Two whole
# cycles are in perf/ (perf/vad_attempt.sh, perf/RESULTS.md).
include(${CMAKE_CURRENT_LIST_DIR}/lib/Checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(root ${CMAKE_CURRENT_LIST_DIR}/../..)
set(python /usr/bin/python3)
execute_process(COMMAND ${python} -c "import numpy" RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
if(rc EQUAL 0)
  execute_process(COMMAND ${python} ${root}/scripts/vad_mesh.py --blood-only ${WORK}/vad_blood.msh RESULT_VARIABLE rc
    OUTPUT_QUIET ERROR_VARIABLE e)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "scripts/vad_mesh.py failed (${rc}): ${e}")
  endif()
  file(SHA256 ${WORK}/vad_blood.msh generated)
  file(SHA256 ${root}/cases/meshes/vad_blood.msh committed)
  if(NOT generated STREQUAL committed)
    message(SEND_ERROR "cases/meshes/vad_blood.msh is not what scripts/vad_mesh.py --blood-only writes")
  endif()
else()
  message(STATUS "numpy missing (/usr/bin/python3): the committed mesh is not compared with the generator's")
endif()
set(membrane membrane)
set(minJacobian 0.5)
stable(vad_start 40 12 ${root}/cases/vad.yaml --set time.endTime=0.04)
file(STRINGS ${WORK}/vad_start/steps.csv rows)
list(GET rows 0 header)
string(REPLACE "," ";" header "${header}")
list(FIND header coupling.chamberPressure col)
list(GET rows -1 last)
string(REPLACE "," ";" last "${last}")
list(GET last ${col} p)
execute_process(COMMAND awk "BEGIN { exit !(${p} > 90 * 133.322 && ${p} < 110 * 133.322) }" RESULT_VARIABLE ok)
if(NOT ok EQUAL 0)
  message(SEND_ERROR "vad_start: the air chamber's pressure at t = 0.04 s is ${p} Pa, outside 90-110 mmHg")
endif()
message(STATUS "vad_start: air chamber at ${p} Pa after 40 ms")
