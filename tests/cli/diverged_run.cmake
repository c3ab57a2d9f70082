# A run that diverges says so and how far it got: the piston with m_a / m = 100 under the explicit
# (staggered) scheme blows up within a few steps. `mfsi run` must exit with code 3, write
# summary.json with status "diverged", the reason, and the steps it completed with the time they
# reached, and steps.csv must hold exactly those steps.
include(${CMAKE_CURRENT_LIST_DIR}/support/summary.cmake)
file(REMOVE_RECURSE ${WORK})
set(out ${WORK}/piston_explicit)
execute_process(COMMAND ${MFSI} run ${CASES}/piston.yaml --set coupling.scheme=explicit --out ${out} --threads 1
  RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 3)
  message(FATAL_ERROR "exit code ${rc}, expected 3 (diverged)\n${e}")
endif()
mfsi_expect_summary(${out} diverged "t = " "explicit piston (the reason must name the step's time)")
set(err "${summary_error}")
set(steps "${summary_steps}")
set(simTime "${summary_sim_time}")
if(steps LESS 1 OR steps GREATER 50)
  message(SEND_ERROR "steps ${steps}: expected the few steps before the blow-up")
endif()
if(NOT simTime GREATER 0)
  message(SEND_ERROR "sim_time ${simTime}: expected the time the completed steps reached")
endif()
file(STRINGS ${out}/steps.csv lines)
list(LENGTH lines n)
math(EXPR rows "${n} - 1")
if(NOT rows EQUAL steps)
  message(SEND_ERROR "steps.csv has ${rows} steps, summary.json says ${steps}")
endif()
message(STATUS "diverged after ${steps} steps at t = ${simTime}: ${err}")

# A steady run that ends before its steady state: exit 5, status "unconverged", the residuals that
# are still too large named; with time.stopAtSteadyState off the same run is an ordinary run.
set(out ${WORK}/cylinder_short)
execute_process(COMMAND ${MFSI} run ${CASES}/cylinder.yaml --set fluid.pimple.outerCorrectors=5 --set time.endTime=2
  --out ${out} --threads 1 RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE e)
if(NOT rc EQUAL 5)
  message(FATAL_ERROR "exit code ${rc}, expected 5 (unconverged)\n${e}")
endif()
mfsi_expect_summary(${out} unconverged "outerTolerance" "cylinder stopped after 10 SIMPLE iterations")
if(NOT summary_steps EQUAL 2)
  message(SEND_ERROR "steps ${summary_steps}: expected the 2 steps asked for")
endif()
execute_process(COMMAND ${MFSI} run ${CASES}/cylinder.yaml --set fluid.pimple.outerCorrectors=5 --set time.endTime=2
  --set time.stopAtSteadyState=false --out ${out} --overwrite --threads 1 RESULT_VARIABLE rc OUTPUT_QUIET
  ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "exit code ${rc} with time.stopAtSteadyState=false, expected 0\n${e}")
endif()
