# `mpiexec -np N mfsi run` of a fluid scene (tests/data/distributed_cavity.yaml): on 2 and 3
# ranks the run gives the one-rank summary metrics (largest speed, the lid's force) and probe
# values to 1e-10, writes one steps.csv, one summary.json (ranks: N) and one field file of the
# whole mesh; a run that diverges on several ranks stops with one message and one summary.
find_program(MPIEXEC mpiexec)
if(NOT MPIEXEC)
  message(STATUS "no mpiexec: skipped")
  return()
endif()
file(REMOVE_RECURSE ${WORK})
set(scene ${DATA}/distributed_cavity.yaml)
set(python /usr/bin/python3)
if(NOT EXISTS ${python})
  find_program(python python3 REQUIRED)
endif()
execute_process(COMMAND ${MFSI} run ${scene} --out ${WORK}/r1 RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "one rank: exit ${rc}\n${o}\n${e}")
endif()
file(READ ${WORK}/r1/summary.json s1)

function(last_row dir out)
  file(STRINGS ${dir}/steps.csv rows)
  list(GET rows 0 header)
  list(GET rows -1 last)
  string(REPLACE "," ";" header "${header}")
  string(REPLACE "," ";" last "${last}")
  set(${out}_header "${header}" PARENT_SCOPE)
  set(${out}_values "${last}" PARENT_SCOPE)
endfunction()
last_row(${WORK}/r1 one)
# same_value(<a> <b> <what>): |a - b| <= 1e-10 |a| with |a| > 1e-6 (CMake's math is integer: awk
# compares the reals).
function(same_value a b what)
  execute_process(COMMAND awk "BEGIN { d = ${a} - (${b}); if (d < 0) d = -d; a = ${a}; if (a < 0) a = -a; exit !(d <= 1e-10 * a && a > 1e-6) }"
    RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(SEND_ERROR "${what}: ${b}, one rank ${a}")
  endif()
endfunction()

foreach(np 2 3)
  execute_process(COMMAND ${MPIEXEC} --allow-run-as-root --oversubscribe -np ${np} ${MFSI} run ${scene}
    --out ${WORK}/r${np} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${np} ranks: exit ${rc}\n${o}\n${e}")
  endif()
  string(REGEX MATCHALL "mfsi [0-9.]+ \\| scene" banners "${o}")
  list(LENGTH banners nb)
  if(NOT nb EQUAL 1)
    message(SEND_ERROR "${np} ranks: ${nb} banners (rank 0 alone prints)")
  endif()
  file(READ ${WORK}/r${np}/summary.json s)
  string(JSON ranks GET "${s}" ranks)
  string(JSON status GET "${s}" status)
  if(NOT ranks EQUAL np OR NOT status STREQUAL "ok")
    message(SEND_ERROR "${np} ranks: summary says ranks ${ranks}, status ${status}")
  endif()
  foreach(key fluid.max_velocity fluid.lid.force_x fluid.lid.force_y)
    string(JSON a GET "${s1}" metrics ${key})
    string(JSON b GET "${s}" metrics ${key})
    same_value(${a} ${b} "${np} ranks: ${key}")
  endforeach()
  last_row(${WORK}/r${np} many)
  if(NOT many_header STREQUAL one_header)
    message(SEND_ERROR "${np} ranks: steps.csv columns differ:\n${many_header}\n${one_header}")
  endif()
  list(FIND one_header fluid.probe.centre.Ux col)
  list(GET one_values ${col} a)
  list(GET many_values ${col} b)
  same_value(${a} ${b} "${np} ranks: probe Ux")
  # Each rank wrote its rows of the frame (no gather): the one-rank frame's datasets, the mesh's
  # points and cells equal, the fields to the solvers' tolerance.
  file(GLOB frames ${WORK}/r${np}/fields/*.h5)
  list(LENGTH frames nf)
  file(GLOB frames1 ${WORK}/r1/fields/*.h5)
  if(NOT nf EQUAL 1)
    message(SEND_ERROR "${np} ranks: ${nf} field files")
  else()
    execute_process(COMMAND ${python} ${CMAKE_CURRENT_LIST_DIR}/support/compare_frames.py ${frames1} ${frames}
      RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
    if(rc EQUAL 77)
      message(STATUS "${np} ranks: frame contents not compared (no h5py): ${o}")
    elseif(NOT rc EQUAL 0)
      message(SEND_ERROR "${np} ranks: the field frame differs from the one-rank frame:\n${o}${e}")
    endif()
    # ParaView's own XDMF reader (where Debian's python3-paraview is) opens it as it opens one rank's.
    execute_process(COMMAND ${python} ${CMAKE_CURRENT_LIST_DIR}/support/check_fields.py ${WORK}/r${np} 1 0
      RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
    if(NOT rc EQUAL 0 AND NOT rc EQUAL 77)
      message(SEND_ERROR "${np} ranks: the fields do not read back:\n${o}${e}")
    endif()
  endif()
endforeach()

# A divergence on several ranks (decided by a global maximum, so on every rank at once): one
# message, exit 3, one summary.json with status "diverged" and the rank count.
execute_process(COMMAND ${MPIEXEC} --allow-run-as-root --oversubscribe -np 2 ${MFSI} run ${scene}
  --set fluid.divergenceVelocityFactor=0.2 --out ${WORK}/dv2 RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
string(REGEX MATCHALL "diverged: fluid: runaway growth" lines "${e}")
list(LENGTH lines nl)
if(NOT rc EQUAL 3 OR NOT nl EQUAL 1)
  message(SEND_ERROR "diverging cavity on 2 ranks: exit ${rc}, ${nl} messages:\n${e}")
endif()
file(READ ${WORK}/dv2/summary.json s)
string(JSON status GET "${s}" status)
string(JSON ranks GET "${s}" ranks)
if(NOT status STREQUAL "diverged" OR NOT ranks EQUAL 2)
  message(SEND_ERROR "diverging cavity on 2 ranks: summary status ${status}, ranks ${ranks}")
endif()

# Patch sums across ranks: a pulsed flow-rate inlet (its profile scaled by its area on all ranks),
# two valved resistance outlets (p = C_r q + p0, q summed over all ranks' faces) and two pressure
# differences (between cells, and between faces of a wall patch) give the
# one-rank answer on 2 ranks to 1e-10.
set(scene ${DATA}/distributed_resistance.yaml)
execute_process(COMMAND ${MFSI} run ${scene} --out ${WORK}/q1 RESULT_VARIABLE rc1 OUTPUT_QUIET ERROR_VARIABLE e1)
execute_process(COMMAND ${MPIEXEC} --allow-run-as-root --oversubscribe -np 2 ${MFSI} run ${scene}
  --out ${WORK}/q2 RESULT_VARIABLE rc2 OUTPUT_QUIET ERROR_VARIABLE e2)
if(NOT rc1 EQUAL 0 OR NOT rc2 EQUAL 0)
  message(FATAL_ERROR "resistance channel: exit ${rc1} on one rank, ${rc2} on two\n${e1}\n${e2}")
endif()
last_row(${WORK}/q1 one)
last_row(${WORK}/q2 many)
foreach(key fluid.probe.centre fluid.probe.centre.Ux fluid.dpAxis fluid.dpWall)
  list(FIND one_header ${key} col)
  list(GET one_values ${col} a)
  list(GET many_values ${col} b)
  same_value(${a} ${b} "resistance channel on 2 ranks: ${key}")
  message(STATUS "resistance channel: ${key} ${b} on 2 ranks, ${a} on one")
endforeach()

# The Ghia comparison on several ranks (every rank's cells gathered on rank 0): the steady cavity
# (16 x 16, solved to 1e-11) gives the one-rank errors on 2 ranks to 1e-10.
set(tight --set fluid.solvers.pressure.relTol=0 --set fluid.solvers.pressure.tolerance=1e-14
  --set fluid.solvers.momentum.relTol=0 --set fluid.solvers.momentum.tolerance=1e-14
  --set fluid.pimple.outerTolerance=1e-11 --set mesh.blocks.0.cells=[16,16,1])
execute_process(COMMAND ${MFSI} run ${CASES}/cavity.yaml ${tight} --out ${WORK}/g1 RESULT_VARIABLE rc1 OUTPUT_QUIET ERROR_VARIABLE e1)
execute_process(COMMAND ${MPIEXEC} --allow-run-as-root --oversubscribe -np 2 ${MFSI} run ${CASES}/cavity.yaml ${tight}
  --out ${WORK}/g2 RESULT_VARIABLE rc2 OUTPUT_QUIET ERROR_VARIABLE e2)
if(NOT rc1 EQUAL 0 OR NOT rc2 EQUAL 0)
  message(FATAL_ERROR "cavity with the Ghia check: exit ${rc1} on one rank, ${rc2} on two\n${e1}\n${e2}")
endif()
file(READ ${WORK}/g1/summary.json s1)
file(READ ${WORK}/g2/summary.json s2)
foreach(key fluid.ghia_u_max_err fluid.ghia_v_max_err)
  string(JSON a GET "${s1}" metrics ${key})
  string(JSON b GET "${s2}" metrics ${key})
  same_value(${a} ${b} "cavity on 2 ranks: ${key}")
  message(STATUS "cavity: ${key} ${b} on 2 ranks, ${a} on one")
endforeach()
