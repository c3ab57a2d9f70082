# The fields of an FSI run as readers see them: tests/cli/support/check_fields.py checks the XDMF
# and HDF5 files with h5py, and loads them in ParaView's own reader where Debian's python3-paraview
# is installed (the set-up installs it). Debian's interpreter, which has h5py and numpy. Two scenes:
# the flexible cavity (block mesh, a membrane) and the cylinder (an unstructured Gmsh mesh, fluid).
file(REMOVE_RECURSE ${WORK})
set(out ${WORK}/cavity)
execute_process(COMMAND ${MFSI} run ${CASES}/flexible-cavity.yaml --set mesh.blocks.0.cells=[12,10,1]
  --set mesh.blocks.1.cells=[12,2,1] --set time.endTime=0.3 --set output.fields.everySteps=2
  --set output.fields.initial=true --out ${out} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mfsi run failed (${rc}):\n${e}")
endif()
set(python /usr/bin/python3)
if(NOT EXISTS ${python})
  find_program(python python3 REQUIRED)
endif()
get_filename_component(here ${CMAKE_CURRENT_LIST_FILE} DIRECTORY)
execute_process(COMMAND ${python} ${here}/support/check_fields.py ${out} 3 RESULT_VARIABLE rc OUTPUT_VARIABLE o
  ERROR_VARIABLE e)
message(STATUS "${o}")
if(rc EQUAL 77)
  message(STATUS "MFSI_SKIP: ${o}")
elseif(NOT rc EQUAL 0)
  message(FATAL_ERROR "check_fields.py (${rc}):\n${o}\n${e}")
endif()

# The cylinder: the scene's unstructured mesh, fluid alone, a frame every step.
set(out ${WORK}/cylinder)
execute_process(COMMAND ${MFSI} run ${CASES}/cylinder.yaml --set fluid.pimple.outerCorrectors=5 --set time.endTime=2
  --set time.stopAtSteadyState=false
  --set output.fields.everySteps=1 --out ${out} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mfsi run cylinder failed (${rc}):\n${e}")
endif()
execute_process(COMMAND ${python} ${here}/support/check_fields.py ${out} 2 0 RESULT_VARIABLE rc OUTPUT_VARIABLE o
  ERROR_VARIABLE e)
message(STATUS "${o}")
if(rc EQUAL 77)
  message(STATUS "MFSI_SKIP: ${o}")
elseif(NOT rc EQUAL 0)
  message(FATAL_ERROR "check_fields.py, cylinder (${rc}):\n${o}\n${e}")
endif()
