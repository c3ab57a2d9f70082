# mfsi plot: on a small 2D FSI run (the flexible cavity, three steps, a field frame at the end) it
# writes valid PNGs of the time series and a field picture into RUN_DIR/plots (or --out) and lists
# them; a folder that is not a run, a run whose steps.csv has a header but no rows and an
# interpreter without matplotlib are refused with exit 2 and a message, nothing written. The
# pictures need a Python with matplotlib: without one the test ends with MFSI_SKIP after the checks
# that do not.
file(REMOVE_RECURSE ${WORK})
set(run ${WORK}/cavity)
execute_process(COMMAND ${MFSI} run ${CASES}/flexible-cavity.yaml --set mesh.blocks.0.cells=[12,10,1]
  --set mesh.blocks.1.cells=[12,2,1] --set time.endTime=0.3 --set output.fields.final=true --out ${run}
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mfsi run failed (${rc}):\n${e}")
endif()

# Not a folder, not a run folder, no interpreter with matplotlib: refused before any drawing.
execute_process(COMMAND ${MFSI} plot ${WORK}/nonexistent RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 2 OR NOT e MATCHES "is not a folder")
  message(SEND_ERROR "plot of a missing folder: exit ${rc} (expected 2), message:\n${e}")
endif()
execute_process(COMMAND ${MFSI} plot ${WORK} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 2 OR NOT e MATCHES "not a run folder: it has no steps.csv")
  message(SEND_ERROR "plot of a folder that is not a run: exit ${rc} (expected 2), message:\n${e}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E env MFSI_PLOT_PYTHON=${WORK}/no-such-python ${MFSI} plot ${run}
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 2 OR NOT e MATCHES "no Python interpreter with matplotlib \\(tried [^ ]*no-such-python"
   OR NOT e MATCHES "apt-get install python3-matplotlib" OR EXISTS ${run}/plots)
  message(SEND_ERROR "plot with an interpreter that cannot run: exit ${rc} (expected 2), message:\n${e}")
endif()

execute_process(COMMAND ${MFSI} plot ${run} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 0 AND e MATCHES "no Python interpreter with matplotlib")
  message(STATUS "MFSI_SKIP: ${e}")
  return()
endif()
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mfsi plot failed (${rc}):\n${o}\n${e}")
endif()

# Every file listed is a PNG of some size, and every PNG of the folder is listed.
function(expect_pngs dir listed names)
  string(STRIP "${listed}" listed)
  string(REPLACE "\n" ";" listed "${listed}")
  file(GLOB found ${dir}/*.png)
  list(SORT found)
  set(sorted ${listed})
  list(SORT sorted)
  if(NOT sorted STREQUAL found)
    message(SEND_ERROR "mfsi plot listed\n  ${listed}\nbut ${dir} holds\n  ${found}")
  endif()
  foreach(f ${listed})
    file(READ ${f} magic LIMIT 8 HEX)
    file(SIZE ${f} size)
    if(NOT magic STREQUAL "89504e470d0a1a0a" OR size LESS 5000)
      message(SEND_ERROR "${f}: not a PNG of some size (first bytes ${magic}, ${size} bytes)")
    endif()
  endforeach()
  foreach(n ${names})
    if(NOT EXISTS ${dir}/${n})
      message(SEND_ERROR "no ${n} in ${dir}: ${listed}")
    endif()
  endforeach()
endfunction()
# A membrane-coupled 2D run: forces on no patch, but membranes, iterations, residuals and the field.
expect_pngs(${run}/plots "${o}" "field.png;membranes.png;iterations.png;residuals.png;coupling.png;timing.png")

# --out, on a run folder of two rows of one fluid column (the pictures of the time series only).
file(WRITE ${WORK}/small/steps.csv "step,time,wall_s,fluid.outerIterations\n1,0.1,0.01,3\n2,0.2,0.02,4\n")
execute_process(COMMAND ${MFSI} plot ${WORK}/small --out ${WORK}/pictures
  RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 0 OR EXISTS ${WORK}/small/plots)
  message(SEND_ERROR "mfsi plot --out: exit ${rc}, or it wrote into RUN_DIR/plots:\n${o}\n${e}")
else()
  expect_pngs(${WORK}/pictures "${o}" "iterations.png;timing.png")
endif()

# A run that took no step (steps.csv header only) and has nothing else to draw: exit 2, said so,
# nothing written.
file(MAKE_DIRECTORY ${WORK}/no-steps)
file(WRITE ${WORK}/no-steps/steps.csv "step,time,wall_s,fluid.outerIterations\n")
execute_process(COMMAND ${MFSI} plot ${WORK}/no-steps RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 2 OR NOT e MATCHES "steps.csv has a header but no rows" OR NOT e MATCHES "nothing to plot"
   OR EXISTS ${WORK}/no-steps/plots)
  message(SEND_ERROR "plot of a run with no rows: exit ${rc} (expected 2, nothing written), message:\n${o}\n${e}")
endif()
