# Shared by the tests/cli scripts and the stability suite (include()d; not a test of its own: the
# suite globs tests/cli/*.cmake).
#
# mfsi_expect_summary(<dir> <status> <text> <context>)
# Reads <dir>/summary.json into the caller's summary_status, summary_error, summary_steps and
# summary_sim_time, and reports an error, prefixed with <context>, when the status is not <status>
# or the error message does not contain <text>.
function(mfsi_expect_summary dir status text context)
  file(READ ${dir}/summary.json js)
  foreach(key status error steps sim_time)
    string(JSON value GET "${js}" ${key})
    set(summary_${key} "${value}" PARENT_SCOPE)
    set(summary_${key} "${value}")
  endforeach()
  if(NOT summary_status STREQUAL status)
    message(SEND_ERROR "${context}: status '${summary_status}', expected '${status}'")
  endif()
  string(FIND "${summary_error}" "${text}" pos)
  if(pos EQUAL -1)
    message(SEND_ERROR "${context}: the error message lacks '${text}': ${summary_error}")
  endif()
endfunction()

# mfsi_last_step(<run dir> <out>): the last row of <run dir>/steps.csv without its wall time (the
# third column), for comparing runs bit for bit.
function(mfsi_last_step dir out)
  file(STRINGS ${dir}/steps.csv rows)
  list(GET rows -1 last)
  string(REGEX REPLACE "^([^,]*,[^,]*,)[^,]*" "\\1" last "${last}")
  set(${out} "${last}" PARENT_SCOPE)
endfunction()
