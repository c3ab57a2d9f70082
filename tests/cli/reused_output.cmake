# An output folder that holds an earlier run's results: a second run into it is refused (exit 2,
# nothing written, the earlier summary untouched); --overwrite removes exactly the earlier results
# (a file of the user's stays) before the new run writes its own; --out naming a file is refused.
file(REMOVE_RECURSE ${WORK})
set(out ${WORK}/run)
execute_process(COMMAND ${MFSI} run ${CASES}/pendulum.yaml --set time.endTime=0.01 --out ${out}
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 0 OR NOT EXISTS ${out}/bodies.csv OR NOT EXISTS ${out}/fields.xdmf)
  message(FATAL_ERROR "first run: exit ${rc}, or no bodies.csv / fields.xdmf:\n${e}")
endif()
file(READ ${out}/summary.json first)
file(WRITE ${out}/notes.txt "the user's own file")

execute_process(COMMAND ${MFSI} run ${CASES}/pendulum.yaml --set time.endTime=0.02 --out ${out}
  RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
string(FIND "${e}" "holds the results of an earlier run" p1)
string(FIND "${e}" "--overwrite" p2)
if(NOT rc EQUAL 2 OR p1 EQUAL -1 OR p2 EQUAL -1)
  message(SEND_ERROR "second run into the same folder: exit ${rc} (expected 2), message:\n${e}")
endif()
file(READ ${out}/summary.json again)
if(NOT again STREQUAL first)
  message(SEND_ERROR "the refused run changed the earlier summary.json")
endif()

# A fluid-only scene with --overwrite: the pendulum's bodies.csv must be gone, the user's file kept.
execute_process(COMMAND ${MFSI} run ${CASES}/cavity.yaml --set time.endTime=0.01 --set mesh.blocks.0.cells=[4,4,1]
  --out ${out} --overwrite RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(SEND_ERROR "--overwrite run: exit ${rc}:\n${e}")
endif()
if(EXISTS ${out}/bodies.csv)
  message(SEND_ERROR "--overwrite left the earlier run's bodies.csv")
endif()
if(NOT EXISTS ${out}/notes.txt)
  message(SEND_ERROR "--overwrite removed a file that was not a result of a run")
endif()
file(GLOB frames ${out}/fields/*.h5)
list(LENGTH frames n)
if(NOT n EQUAL 1)
  message(SEND_ERROR "--overwrite: ${n} field frames, expected the new run's one: ${frames}")
endif()

execute_process(COMMAND ${MFSI} run ${CASES}/pendulum.yaml --out ${out}/notes.txt
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
string(FIND "${e}" "is a file" p)
if(NOT rc EQUAL 2 OR p EQUAL -1)
  message(SEND_ERROR "--out naming a file: exit ${rc} (expected 2):\n${e}")
endif()
