# Checks shared by the glint-bench test scripts (run_bench*.cmake), on the
# files a run wrote: whether it measured every configuration it planned
# (report.h's RunInfo::configurationsPlanned and cutShort).

# The run whose JSON is JSON_PATH planned PLANNED configurations and was
# not cut short.
function(bench_require_ran_to_end JSON_PATH PLANNED)
  file(READ ${JSON_PATH} json)
  string(JSON planned GET "${json}" configurations_planned)
  string(JSON cut GET "${json}" cut_short)
  if(NOT planned EQUAL PLANNED OR NOT cut STREQUAL "OFF")
    message(FATAL_ERROR "${JSON_PATH}: configurations_planned ${planned}, cut_short ${cut}; expected ${PLANNED} and false")
  endif()
endfunction()

# A run whose --time-limit passed before its first configuration: the CSV
# holds its header alone, the JSON no row of the PLANNED and cut_short true.
function(bench_require_cut_short_before_start CSV_PATH JSON_PATH PLANNED)
  file(STRINGS ${CSV_PATH} lines)
  list(LENGTH lines count)
  file(READ ${JSON_PATH} json)
  string(JSON rows LENGTH "${json}" rows)
  string(JSON planned GET "${json}" configurations_planned)
  string(JSON cut GET "${json}" cut_short)
  if(NOT count EQUAL 1 OR NOT rows EQUAL 0 OR NOT planned EQUAL PLANNED OR NOT cut STREQUAL "ON")
    message(FATAL_ERROR "${CSV_PATH}, ${JSON_PATH}: ${count} CSV lines, ${rows} rows of ${planned} planned, "
                        "cut_short ${cut}; expected the header alone, 0 of ${PLANNED}, true")
  endif()
endfunction()
