# Shared checks of the stability suite (tests/stability/*.cmake): a run that must stay stable, and
# a run that must stop as diverged. Each writes one line for the suite's table to the test log.

# stable(<name> <steps> <iterationLimit> <args...>): `mfsi run <args>` completes all <steps> steps
# with exit 0 and status ok; every step's coupling loop converged (none unconverged, none over
# <iterationLimit> iterations); no NaN or Inf anywhere in steps.csv; the mesh valid (minimum scaled
# Jacobian over the run > ${minJacobian}, default 0.5); the membrane's largest displacement finite
# and below ${maxDisplacement} (default 0.5, half the cavity: bounded). The membrane is ${membrane}
# (default bottom).
function(stable name steps limit)
  if(NOT DEFINED minJacobian)
    set(minJacobian 0.5)
  endif()
  if(NOT DEFINED membrane)
    set(membrane bottom)
  endif()
  if(NOT DEFINED maxDisplacement)
    set(maxDisplacement 0.5)
  endif()
  execute_process(COMMAND ${MFSI} run ${ARGN} --out ${WORK}/${name} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  if(NOT rc EQUAL 0)
    message(SEND_ERROR "${name}: exit ${rc} (must stay stable)\n${e}")
    return()
  endif()
  file(READ ${WORK}/${name}/summary.json s)
  string(JSON status GET "${s}" status)
  string(JSON done GET "${s}" steps)
  string(JSON unconverged GET "${s}" metrics coupling.unconverged_steps)
  string(JSON worst GET "${s}" metrics coupling.max_iterations)
  string(JSON mean GET "${s}" metrics coupling.mean_iterations)
  string(JSON jac GET "${s}" metrics coupling.min_scaled_jacobian)
  string(JSON umax GET "${s}" metrics membrane.${membrane}.maxDisplacement)
  # MATCHES, not STREQUAL "ok": a script's own variable named ok would stand in for the string.
  if(NOT status MATCHES "^ok$" OR NOT done EQUAL steps OR NOT unconverged EQUAL 0 OR worst GREATER limit)
    message(SEND_ERROR "${name}: status ${status}, ${done} of ${steps} steps, ${unconverged} unconverged, "
      "at most ${worst} iterations (limit ${limit})")
  endif()
  execute_process(COMMAND awk "BEGIN { exit !(${jac} > ${minJacobian} && ${umax} == ${umax} && ${umax} < ${maxDisplacement}) }"
    RESULT_VARIABLE ok)
  if(NOT ok EQUAL 0)
    message(SEND_ERROR "${name}: minimum scaled Jacobian ${jac}, largest membrane displacement ${umax}")
  endif()
  file(READ ${WORK}/${name}/steps.csv rows)
  string(TOLOWER "${rows}" rows)
  if(rows MATCHES "nan|inf")
    message(SEND_ERROR "${name}: NaN or Inf in steps.csv")
  endif()
  message(STATUS "| ${name} | stable: ${done} steps, ${mean} its/step (max ${worst}), min scaled Jacobian ${jac}, max |u| ${umax} |")
endfunction()

# diverges(<name> <steps> <args...>): `mfsi run <args>` stops before step <steps> with exit 3,
# status diverged and its reason, within 60 s of wall time.
function(diverges name steps)
  execute_process(COMMAND ${MFSI} run ${ARGN} --out ${WORK}/${name} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  file(READ ${WORK}/${name}/summary.json s)
  string(JSON status GET "${s}" status)
  string(JSON done GET "${s}" steps)
  string(JSON why GET "${s}" error)
  string(JSON wall GET "${s}" wall_s)
  if(NOT rc EQUAL 3 OR NOT status MATCHES "^diverged$" OR NOT done LESS steps OR why STREQUAL "")
    message(SEND_ERROR "${name}: exit ${rc}, status ${status} after ${done} of ${steps} steps (must diverge)")
  endif()
  execute_process(COMMAND awk "BEGIN { exit !(${wall} < 60) }" RESULT_VARIABLE ok)
  if(NOT ok EQUAL 0)
    message(SEND_ERROR "${name}: took ${wall} s to stop")
  endif()
  message(STATUS "| ${name} | diverged at step ${done}: ${why} |")
endfunction()
