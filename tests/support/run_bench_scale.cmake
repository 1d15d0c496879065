# Runs glint-bench --scale (BENCH) small: two sizes of a coarse city, tiny
# and short, validation on, writing CSV, JSON and plot under OUT. Checks the
# exit code, the files, the CSV header, a row per size and mode with both
# reflection times, the instanced triangles growing with the size, the
# JSON's per-pass times and the occlusion cull's counts, that it ran to
# the end; then a run whose --time-limit has passed before the first size.
cmake_policy(SET CMP0054 NEW)
include(${CMAKE_CURRENT_LIST_DIR}/bench_checks.cmake)
file(REMOVE ${OUT}/scale.csv ${OUT}/scale.json ${OUT}/scale.png)
execute_process(COMMAND ${BENCH} --validate --scale 16,32 --scene city:triangles=2000 --size 64x36 --frames 3
                        --reference-max-frames 8 --out-dir ${OUT}
                        --csv ${OUT}/scale.csv --json ${OUT}/scale.json --plot ${OUT}/scale.png
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glint-bench --scale exited with ${rc}")
endif()
foreach(f scale.csv scale.json scale.png)
  if(NOT EXISTS ${OUT}/${f})
    message(FATAL_ERROR "glint-bench --scale did not write ${OUT}/${f}")
  endif()
endforeach()
file(STRINGS ${OUT}/scale.csv lines)
list(GET lines 0 header)
set(expected "scene,mode,instances,triangles,width,height,reflection_ms,reflection_span_ms,total_ms,rt_rays,sslr_rays,flip_mean,reflection_mean_ms,reflection_span_mean_ms")
if(NOT header STREQUAL expected)
  message(FATAL_ERROR "${OUT}/scale.csv: header '${header}', expected '${expected}'")
endif()
list(LENGTH lines count)
if(NOT count EQUAL 7)
  message(FATAL_ERROR "${OUT}/scale.csv: ${count} lines, expected a header and 2 sizes x 3 modes")
endif()
set(triangles "")
foreach(size 16 32)
  foreach(mode hybrid ssr rt)
    # Both times present (numbers, not empty cells).
    if(NOT "${lines}" MATCHES "city,${mode},${size},([0-9]+),64,36,[0-9.e+-]+,[0-9.e+-]+,[0-9.e+-]+,")
      message(FATAL_ERROR "${OUT}/scale.csv: no complete row for ${mode} at ${size} instances")
    endif()
  endforeach()
  string(REGEX MATCH "city,hybrid,${size},([0-9]+)," row "${lines}")
  list(APPEND triangles ${CMAKE_MATCH_1})
endforeach()
list(GET triangles 0 small)
list(GET triangles 1 large)
if(NOT large GREATER small)
  message(FATAL_ERROR "${OUT}/scale.csv: ${large} triangles at 32 instances, not more than ${small} at 16")
endif()
file(READ ${OUT}/scale.json json)
string(JSON jrows LENGTH "${json}" rows)
if(NOT jrows EQUAL 6)
  message(FATAL_ERROR "${OUT}/scale.json: ${jrows} rows, expected 6")
endif()
bench_require_ran_to_end(${OUT}/scale.json 6)
string(JSON ms ERROR_VARIABLE err GET "${json}" rows 0 passes gbuffer)
if(err)
  message(FATAL_ERROR "${OUT}/scale.json: no per-pass times: ${err}")
endif()
# The G-buffer's occlusion cull ran: the triangles it drew are counted on
# the GPU, and they are no more than the instanced triangles.
string(JSON drawn ERROR_VARIABLE err GET "${json}" rows 5 triangles_drawn)
string(JSON occluded ERROR_VARIABLE err2 GET "${json}" rows 5 instances_occluded)
if(err OR err2)
  message(FATAL_ERROR "${OUT}/scale.json: no occlusion counts: ${err} ${err2}")
endif()
if(drawn GREATER large)
  message(FATAL_ERROR "${OUT}/scale.json: ${drawn} triangles drawn of ${large}")
endif()
message(STATUS "glint-bench --scale: ${small} and ${large} instanced triangles, ${drawn} drawn at 32 instances "
               "(${occluded} instances occluded)")

# --time-limit that has passed before the first size: no city is built or
# measured; the CSV holds its header alone and the JSON says the run was
# cut short of its 2 sizes x 3 modes.
file(REMOVE ${OUT}/scale_limit.csv ${OUT}/scale_limit.json)
execute_process(COMMAND ${BENCH} --validate --scale 16,32 --scene city:triangles=2000 --size 64x36 --frames 3
                        --time-limit 0.001 --out-dir ${OUT}
                        --csv ${OUT}/scale_limit.csv --json ${OUT}/scale_limit.json --plot ${OUT}/scale_limit.png
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glint-bench --scale --time-limit exited with ${rc}")
endif()
bench_require_cut_short_before_start(${OUT}/scale_limit.csv ${OUT}/scale_limit.json 6)
