# Wrinkling in flow (tests/data/wrinkling_in_flow.yaml): a pre-tensioned panel across a flow whose
# frame closes in on it (two opposite edges clamped and moved together: 10 % compression, against a
# pre-stress worth 1 %). With the tension-field model the coupling converges every step, the sheet
# carries no compression (smallest principal stress >= 0), most of it is wrinkled, and it billows
# downstream like a sail (the centre moves with the flow). Without the model it converges too, but
# carries the compression a membrane cannot (a smallest principal stress of about -12 N/m over
# h = 1 mm) and buckles: that is what the model is for.
include(${CMAKE_CURRENT_LIST_DIR}/lib/Checks.cmake)
file(REMOVE_RECURSE ${WORK})
set(membrane panel)
set(scene ${CMAKE_CURRENT_LIST_DIR}/../data/wrinkling_in_flow.yaml)

function(panel_state name)
  file(READ ${WORK}/${name}/summary.json s)
  foreach(k minPrincipalStress wrinkledFraction slackFraction centreUx)
    string(JSON v GET "${s}" metrics membrane.panel.${k})
    set(${k} ${v} PARENT_SCOPE)
  endforeach()
endfunction()

stable(tension_field 30 10 ${scene})
panel_state(tension_field)
message(STATUS "| wrinkling, tension field | smallest principal stress ${minPrincipalStress} Pa, wrinkled ${wrinkledFraction}, slack ${slackFraction}, centre moved ${centreUx} m along the flow |")
execute_process(COMMAND awk "BEGIN { exit !(${minPrincipalStress} >= 0 && ${wrinkledFraction} >= 0.5 && ${centreUx} > 0.01) }"
  RESULT_VARIABLE bad)
if(NOT bad EQUAL 0)
  message(SEND_ERROR "tension field: the sheet must wrinkle, carry no compression and billow downstream")
endif()

stable(no_model 30 10 ${scene} --set membranes.0.wrinkling=none)
panel_state(no_model)
message(STATUS "| wrinkling, no model | smallest principal stress ${minPrincipalStress} Pa, centre moved ${centreUx} m along the flow |")
execute_process(COMMAND awk "BEGIN { exit !(${minPrincipalStress} < -5000) }" RESULT_VARIABLE bad)
if(NOT bad EQUAL 0)
  message(SEND_ERROR "no wrinkling model: the sheet was expected to carry the compression (${minPrincipalStress} Pa)")
endif()
