# The Kokkos 4 API guard can fail: on the fixture with one use of each rejected construct, it must
# exit non-zero and report every rule once (-DSCRIPT=check-kokkos-api.sh -DFIXTURE=removed_api.cpp).
execute_process(COMMAND bash ${SCRIPT} --count-rules OUTPUT_VARIABLE rules OUTPUT_STRIP_TRAILING_WHITESPACE)
execute_process(COMMAND bash ${SCRIPT} ${FIXTURE} RESULT_VARIABLE rc OUTPUT_VARIABLE out)
string(REGEX MATCHALL "Kokkos 4: " hits "${out}")
list(LENGTH hits n)
if(rc EQUAL 0 OR NOT n EQUAL rules)
  message(FATAL_ERROR "guard exit ${rc}, ${n} findings for ${rules} rules:\n${out}")
endif()
message(STATUS "guard rejects all ${rules} constructs of the fixture")
