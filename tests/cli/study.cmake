# mfsi study: on the membrane square at 4x4 to 8x8 cells (under a second a run) it writes study.csv with
# one row per setting, study.json with the observed order and the PNGs; run again it re-runs nothing
# (the summaries keep their times) and one more setting, whose scene is invalid, runs alone and
# becomes a row with status error (exit 0); the fits recover known orders from synthetic errors
# (study.py --self-test, by the interpreter mfsi study uses); bad input exits 2 with a message
# before any run (bad --vary, unknown scene, bad --reference, finest without a numeric key) or after
# the runs for a metric no run reports (did you mean ...); SIGINT stops the study with exit 130 and
# the table of what is done. The study needs a Python with matplotlib: without one the test ends
# with MFSI_SKIP after the check that says so.
file(REMOVE_RECURSE ${WORK})
set(out ${WORK}/square)
set(cells membranes.0.mesh.rectangle.cells)

execute_process(COMMAND ${CMAKE_COMMAND} -E env MFSI_PLOT_PYTHON=${WORK}/no-such-python ${MFSI} study
  membrane-square --vary ${cells}=[4,4],[6,6] --metric membrane.period --reference exact --out ${out}
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 2 OR NOT e MATCHES "no Python interpreter with matplotlib" OR EXISTS ${out})
  message(SEND_ERROR "study with an interpreter that cannot run: exit ${rc} (expected 2), message:\n${e}")
endif()

execute_process(COMMAND ${MFSI} study --self-test RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 0 AND e MATCHES "no Python interpreter with matplotlib")
  message(STATUS "MFSI_SKIP: ${e}")
  return()
endif()
if(NOT rc EQUAL 0 OR NOT o MATCHES "self-test passed"
   OR NOT o MATCHES "ok    order from cell counts 8..128 with C h\\^2 errors: 2\\.0")
  message(SEND_ERROR "study --self-test failed (${rc}):\n${o}\n${e}")
endif()

# Bad input: refused before any run, nothing written.
function(expect_bad_input what pattern)
  execute_process(COMMAND ${MFSI} study ${ARGN} --out ${WORK}/bad RESULT_VARIABLE rc OUTPUT_VARIABLE o
    ERROR_VARIABLE e)
  if(NOT rc EQUAL 2 OR NOT e MATCHES "${pattern}" OR EXISTS ${WORK}/bad)
    message(SEND_ERROR "${what}: exit ${rc} (expected 2 and '${pattern}', nothing written):\n${o}\n${e}")
  endif()
endfunction()
expect_bad_input("--vary without values" "--vary 'mesh.refine': expected KEY=V1,V2"
  cavity --vary mesh.refine --metric fluid.ghia_u_max_err --reference 0)
expect_bad_input("unknown scene" "scene 'no-such-scene': cannot open scene file"
  no-such-scene --vary mesh.refine=1,2 --metric fluid.ghia_u_max_err --reference 0)
expect_bad_input("bad --reference" "--reference 'closest': expected exact, exact:METRIC, finest, richardson or a number"
  cavity --vary mesh.refine=1,2 --metric fluid.ghia_u_max_err --reference closest)
expect_bad_input("finest without a numeric key" "--reference finest needs a numeric --vary"
  cavity --vary fluid.convection=upwind,linear --metric fluid.ghia_u_max_err --reference finest)
expect_bad_input("no --metric" "mfsi study needs SCENE, --vary" cavity --vary mesh.refine=1,2 --reference 0)

# The study: three settings, two at once.
set(study ${MFSI} study membrane-square --metric membrane.period --reference exact --jobs 2 --threads 2 --out ${out})
execute_process(COMMAND ${study} --vary ${cells}=[4,4],[6,6],[8,8] RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mfsi study failed (${rc}):\n${o}\n${e}")
endif()
if(NOT o MATCHES "0 done already \\(reused\\), 3 to run" OR NOT o MATCHES "observed order along ${cells}: [0-9.]+")
  message(SEND_ERROR "the study does not say what it ran and the order it observed:\n${o}")
endif()
file(STRINGS ${out}/study.csv rows)
list(LENGTH rows n)
list(GET rows 0 header)
if(NOT n EQUAL 4 OR NOT header MATCHES "^id,${cells},status,steps,wall_s,cpu_s,process_s,max_rss_mb,metric,reference,error,")
  message(SEND_ERROR "study.csv: expected a header and 3 rows, got ${n} lines:\n${rows}")
endif()
foreach(c 4x4 6x6 8x8)
  if(NOT rows MATCHES "cells=${c},[^;]*,ok,100,[0-9.e-]+,[0-9.e-]+,")
    message(SEND_ERROR "study.csv has no ok row of cells ${c} with its steps, wall and CPU time:\n${rows}")
  endif()
endforeach()
foreach(png error_vs_wall.png error_vs_cells.png)
  file(READ ${out}/${png} magic LIMIT 8 HEX)
  if(NOT magic STREQUAL "89504e470d0a1a0a")
    message(SEND_ERROR "${out}/${png}: not a PNG")
  endif()
endforeach()
file(READ ${out}/study.json json)
string(JSON order GET "${json}" orders 0 order)
if(order LESS 1.5 OR order GREATER 3)
  message(SEND_ERROR "observed order of the period error ${order}: expected about 2 (Newmark, bilinear membrane)")
endif()

# Resumed, with one more setting that cannot run (no cells): only that one runs; it is a row.
set(stamps "")
foreach(c 4x4 6x6 8x8)
  file(TIMESTAMP ${out}/runs/cells=${c}/summary.json t "%s%f")
  list(APPEND stamps ${t})
endforeach()
execute_process(COMMAND ${study} --vary ${cells}=[4,4],[6,6],[8,8],[0,0] RESULT_VARIABLE rc OUTPUT_VARIABLE o
  ERROR_VARIABLE e)
if(NOT rc EQUAL 0 OR NOT o MATCHES "3 done already \\(reused\\), 1 to run" OR NOT o MATCHES "\\[1/1\\] ${cells}=\\[0,0\\]: error")
  message(SEND_ERROR "resumed study with a failing setting: exit ${rc} (expected 0, 3 reused, 1 run):\n${o}\n${e}")
endif()
set(i 0)
foreach(c 4x4 6x6 8x8)
  file(TIMESTAMP ${out}/runs/cells=${c}/summary.json t "%s%f")
  list(GET stamps ${i} before)
  if(NOT t STREQUAL before)
    message(SEND_ERROR "cells ${c} was run again on resume (summary.json ${before} -> ${t})")
  endif()
  math(EXPR i "${i} + 1")
endforeach()
file(STRINGS ${out}/study.csv rows)
list(LENGTH rows n)
if(NOT n EQUAL 5 OR NOT rows MATCHES "cells=0x0,\"\\[0,0\\]\",error,[^;]*membranes.0.mesh.rectangle.cells")
  message(SEND_ERROR "study.csv: expected 4 rows, the last with status error and the reason:\n${rows}")
endif()

# The same study again: nothing to run; a metric no run reports is bad input with a suggestion.
execute_process(COMMAND ${study} --vary ${cells}=[4,4],[6,6],[8,8],[0,0] RESULT_VARIABLE rc OUTPUT_VARIABLE o
  ERROR_VARIABLE e)
if(NOT rc EQUAL 0 OR NOT o MATCHES "4 done already \\(reused\\), 0 to run")
  message(SEND_ERROR "a finished study run again: exit ${rc} (expected 0 and nothing to run):\n${o}\n${e}")
endif()
# Against the Richardson limit of the three finest runs (no run again): every run has an error,
# the finest too, and the limit is the exact period's to the time step's error (0.2 %).
string(REPLACE "--reference;exact" "--reference;richardson" rich "${study}")
execute_process(COMMAND ${rich} --vary ${cells}=[4,4],[6,6],[8,8] RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 0 OR NOT o MATCHES "0 to run" OR NOT o MATCHES "Richardson limit of membrane.period")
  message(SEND_ERROR "--reference richardson: exit ${rc} (expected 0, nothing run, the limit):\n${o}\n${e}")
endif()
file(READ ${out}/study.json json)
string(JSON limit GET "${json}" richardson 0 limit)
if(limit LESS 0.1400 OR limit GREATER 0.1428)
  message(SEND_ERROR "Richardson limit of the period ${limit}: expected the exact 0.14142 within 1 %")
endif()
file(STRINGS ${out}/study.csv rows)
if(NOT rows MATCHES "cells=8x8,\"\\[8,8\\]\",ok,[^;]*,0\\.14[0-9]+,0\\.14[0-9]+,0\\.00[1-9]")
  message(SEND_ERROR "study.csv: the finest run (8x8) has no error of its own against the limit:\n${rows}")
endif()
string(REPLACE "membrane.period" "membrane.perod" typo "${study}")
execute_process(COMMAND ${typo} --vary ${cells}=[4,4],[6,6],[8,8] RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 2 OR NOT e MATCHES "no run reports the metric 'membrane.perod'; did you mean membrane.period"
   OR NOT o MATCHES "0 to run")
  message(SEND_ERROR "unknown metric: exit ${rc} (expected 2, runs reused, a suggestion):\n${o}\n${e}")
endif()

# SIGINT (sent to mfsi alone, as `kill` does) once a run has begun its steps: the run stops after its
# step, the second is never started, the table says so, exit 130.
find_program(SH sh)
if(SH)
  set(long ${WORK}/interrupted)
  execute_process(COMMAND ${SH} -c "\"$0\" study membrane-square --vary '${cells}=[6,6],[8,8]' \
--set time.endTime=1000 --metric membrane.period --reference exact --threads 1 --out '${long}' & pid=$!; i=0; \
while ! ls '${long}'/runs/*/steps.csv >/dev/null 2>&1 && [ $i -lt 600 ]; do sleep 0.1; i=$((i+1)); done; \
sleep 0.3; kill -INT $pid; wait $pid" ${MFSI} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  file(STRINGS ${long}/study.csv rows)
  if(NOT rc EQUAL 130 OR NOT o MATCHES "stopped by SIGINT" OR NOT rows MATCHES "cells=6x6,[^;]*,interrupted,"
     OR NOT rows MATCHES "cells=8x8,[^;]*,not run," OR EXISTS ${long}/runs/cells=8x8)
    message(SEND_ERROR "interrupted study: exit ${rc} (expected 130, one run interrupted, one not run):\n${o}\n${e}\n${rows}")
  endif()
endif()
