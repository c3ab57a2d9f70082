# The pulsatile VAD's first 40 ms (cases/vad.yaml on the blood chamber's mesh
# cases/meshes/vad_blood.msh, which scripts/vad_mesh.py --blood-only writes byte for byte: checked
# here where numpy is installed): the air chamber, lumped behind the membrane, fills at the
# ejection pulse's rate and pushes the domed membrane (plate bending, tension field with a residual
# stiffness) into the blood, which leaves through the open outlet's resistance. Every step's
# coupling converges (measured 4.03 iterations per step, 10 at most; asserted at most 12), the mesh
# keeps its starting quality, and the air chamber's pressure climbs from p0 = 65 mmHg to the
# outlet's working range: above the outlet's p0 + C_r q = 88 mmHg at t = 0.04 s (q = 169 cm^3/s)
# by what drives the blood through the chamber (measured 98.7 mmHg; asserted 90-110). Two whole
# cycles are in perf/ (perf/vad_attempt.sh, perf/RESULTS.md).
# Then the same 40 ms with the air chamber meshed (cases/vad-two-chambers.yaml on
# cases/meshes/vad.msh, what scripts/vad_mesh.py writes: checked likewise): air of its own density
# and viscosity (fluid.regions) above the membrane baffle, filled through the air port, closed to
# pressure (the volume constraint). Its inertia is negligible, so its mean pressure is the lumped
# chamber's (measured 0.002 % apart at t = 0.04 s, the outlet's pressure 0.002 %; asserted 0.1 %),
# uniform (the probe under the port within 0.1 % of the mean), and the coupling as quick (measured
# 4.0 iterations per step, 9 at most).
include(${CMAKE_CURRENT_LIST_DIR}/lib/Checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(root ${CMAKE_CURRENT_LIST_DIR}/../..)
set(python /usr/bin/python3)
# The committed mesh cases/meshes/<mesh> is byte for byte what scripts/vad_mesh.py <args> writes.
function(check_committed mesh)
  execute_process(COMMAND ${python} ${root}/scripts/vad_mesh.py ${ARGN} ${WORK}/${mesh} RESULT_VARIABLE rc
    OUTPUT_QUIET ERROR_VARIABLE e)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "scripts/vad_mesh.py failed (${rc}): ${e}")
  endif()
  file(SHA256 ${WORK}/${mesh} generated)
  file(SHA256 ${root}/cases/meshes/${mesh} committed)
  if(NOT generated STREQUAL committed)
    message(SEND_ERROR "cases/meshes/${mesh} is not what scripts/vad_mesh.py ${ARGN} writes")
  endif()
endfunction()
execute_process(COMMAND ${python} -c "import numpy" RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
if(rc EQUAL 0)
  check_committed(vad_blood.msh --blood-only)
  check_committed(vad.msh)
else()
  message(STATUS "numpy missing (/usr/bin/python3): the committed meshes are not compared with the generator's")
endif()
set(membrane membrane)
set(minJacobian 0.5)
stable(vad_start 40 12 ${root}/cases/vad.yaml --set time.endTime=0.04)
# The last step's value of column `column` of run `name`'s steps.csv, in `out`.
function(last_value name column out)
  file(STRINGS ${WORK}/${name}/steps.csv rows)
  list(GET rows 0 header)
  string(REPLACE "," ";" header "${header}")
  list(FIND header ${column} col)
  if(col LESS 0)
    message(FATAL_ERROR "${name}: no column ${column} in steps.csv")
  endif()
  list(GET rows -1 last)
  string(REPLACE "," ";" last "${last}")
  list(GET last ${col} v)
  set(${out} ${v} PARENT_SCOPE)
endfunction()
last_value(vad_start coupling.chamberPressure p)
last_value(vad_start fluid.bloodOutlet.pressure pOut)
execute_process(COMMAND awk "BEGIN { exit !(${p} > 90 * 133.322 && ${p} < 110 * 133.322) }" RESULT_VARIABLE ok)
if(NOT ok EQUAL 0)
  message(SEND_ERROR "vad_start: the air chamber's pressure at t = 0.04 s is ${p} Pa, outside 90-110 mmHg")
endif()
message(STATUS "vad_start: air chamber at ${p} Pa after 40 ms")

stable(vad_two_chambers 40 12 ${root}/cases/vad-two-chambers.yaml --set time.endTime=0.04)
last_value(vad_two_chambers coupling.chamberPressure p2)
last_value(vad_two_chambers fluid.probe.air probe)
last_value(vad_two_chambers fluid.bloodOutlet.pressure pOut2)
execute_process(COMMAND awk "BEGIN { d = ${p2} / ${p} - 1; o = ${pOut2} / ${pOut} - 1; u = ${probe} / ${p2} - 1
  exit !(d < 1e-3 && d > -1e-3 && o < 1e-3 && o > -1e-3 && u < 1e-3 && u > -1e-3) }" RESULT_VARIABLE ok)
if(NOT ok EQUAL 0)
  message(SEND_ERROR "vad_two_chambers at t = 0.04 s: the meshed air chamber's mean pressure ${p2} Pa (lumped ${p}), "
    "under the port ${probe}; the outlet's ${pOut2} Pa (lumped ${pOut}): not within 0.1 %")
endif()
message(STATUS "vad_two_chambers: the meshed air chamber at ${p2} Pa (lumped ${p}), the outlet at ${pOut2} Pa "
  "(lumped ${pOut}) after 40 ms")
