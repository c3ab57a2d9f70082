# Large deflection: the flexible-bottom cavity (12 x 12) with its membrane pushed into the cavity
# by a pressure from below (coupling.outsidePressure, ramped over 3 s, 6 s in all). With the mesh
# motion's edge stiffness growing near the membrane (meshMotion.distanceExponent 1) it stays valid
# while the mid-point rises to 0.44 and 0.46 of the span (P = 0.75 and 0.85 Pa); with uniform
# stiffness the motion folds a cell at 0.42 (diverged, with the reason). With columns (each line of
# cells from the membrane to the lid compresses alike, meshMotion.columns) it reaches half the span:
# 0.516 at P = 1.2 Pa (minimum scaled Jacobian 0.10 when the mid-point passes 0.5, 0.030 at worst).
include(${CMAKE_CURRENT_LIST_DIR}/lib/Checks.cmake)
file(REMOVE_RECURSE ${WORK})
set(cavity flexible-cavity --set mesh.blocks.0.cells=[12,10,1] --set mesh.blocks.1.cells=[12,2,1] --set time.endTime=6
  --set coupling.fsiRampTime=3)
set(minJacobian 0.02)
stable(pushed_0.75 60 8 ${cavity} --set coupling.outsidePressure=0.75 --set coupling.meshMotion.distanceExponent=1)
stable(pushed_0.85 60 8 ${cavity} --set coupling.outsidePressure=0.85 --set coupling.meshMotion.distanceExponent=1)
diverges(pushed_0.75_uniform 60 ${cavity} --set coupling.outsidePressure=0.75)
set(maxDisplacement 0.6)  # bounded: three fifths of the cavity
stable(pushed_1.2_columns 60 8 ${cavity} --set coupling.outsidePressure=1.2 --set coupling.meshMotion.columns=true)
# The rise itself: above 0.43 of the span at P = 0.75, above half the span with columns at P = 1.2.
function(highest_rise run limit)
  file(STRINGS ${WORK}/${run}/steps.csv rows)
  list(GET rows 0 header)
  string(REPLACE "," ";" header "${header}")
  list(FIND header membrane.bottom.centreUy col)
  set(top 0)
  foreach(r ${rows})
    string(REPLACE "," ";" v "${r}")
    list(GET v ${col} u)
    if(u MATCHES "^[0-9.eE+-]+$")
      execute_process(COMMAND awk "BEGIN { exit !(${u} > ${top}) }" RESULT_VARIABLE higher)
      if(higher EQUAL 0)
        set(top ${u})
      endif()
    endif()
  endforeach()
  execute_process(COMMAND awk "BEGIN { exit !(${top} > ${limit}) }" RESULT_VARIABLE ok)
  if(NOT ok EQUAL 0)
    message(SEND_ERROR "${run}: the mid-point rose to ${top} of the span only (limit ${limit})")
  endif()
  message(STATUS "${run}: the mid-point rose to ${top} of the span")
endfunction()
highest_rise(pushed_0.75 0.43)
highest_rise(pushed_1.2_columns 0.5)
