# A run of a scene whose mesh is a file named relative to the scene (cases/vad-two-chambers.yaml:
# meshes/vad.msh) continues from its checkpoint with `mfsi run --restart <checkpoint>`: the scene
# then comes from the run's copy, <out>/scene.yaml, which names the mesh by its absolute path
# (Schema::path). The continued steps are the uninterrupted run's, bit for bit (the wall time left
# out).
include(${CMAKE_CURRENT_LIST_DIR}/support/summary.cmake)
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${MFSI} run ${CASES}/vad-two-chambers.yaml --set time.endTime=0.004
  --set output.checkpoint.everySteps=2 --out ${WORK}/whole RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the run failed (${rc}): ${e}")
endif()
file(STRINGS ${WORK}/whole/scene.yaml lines REGEX "^  file: ")
if(NOT lines MATCHES "file: /.*/cases/meshes/vad.msh")
  message(SEND_ERROR "the run's scene.yaml names its mesh as '${lines}', not by an absolute path")
endif()
execute_process(COMMAND ${MFSI} run --restart ${WORK}/whole/checkpoints/checkpoint_000000002.h5 --out ${WORK}/continued
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the restart failed (${rc}): ${e}")
endif()
mfsi_last_step(${WORK}/whole la)
mfsi_last_step(${WORK}/continued lb)
if(NOT la STREQUAL lb OR NOT la MATCHES "^4,")
  message(SEND_ERROR "the continued run ends differently:\n${la}\n${lb}")
endif()
message(STATUS "restart from a run of a scene with a mesh file: step 4 the same")
