# Runs glint-bench (BENCH) as a quick smoke test: --quick on the plaza, tiny
# and short, validation on, writing CSV, JSON and plot under OUT. Checks the
# exit code, that the three files exist, the CSV header report.h states,
# no frame of ssr or rt rendered "as rt" by the hybrid's gate,
# a row per configuration (three mode defaults and the quick sweeps), the
# JSON's provenance keys and that it ran to the end; then a run whose
# --time-limit has passed.
cmake_policy(SET CMP0054 NEW)
include(${CMAKE_CURRENT_LIST_DIR}/bench_checks.cmake)
file(REMOVE ${OUT}/bench.csv ${OUT}/bench.json ${OUT}/bench.png ${OUT}/bench.svg)
execute_process(COMMAND ${BENCH} --validate --scene plaza --quick --size 64x48 --frames 3
                        --reference-max-frames 64 --out-dir ${OUT}
                        --csv ${OUT}/bench.csv --json ${OUT}/bench.json --plot ${OUT}/bench.png
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glint-bench exited with ${rc}")
endif()
foreach(f bench.csv bench.json bench.png bench.svg bench.plot.json bench.plot.py)
  if(NOT EXISTS ${OUT}/${f})
    message(FATAL_ERROR "glint-bench did not write ${OUT}/${f}")
  endif()
endforeach()
file(STRINGS ${OUT}/bench.csv lines)
list(GET lines 0 header)
set(expected "scene,mode,param,value,width,height,reflection_ms,total_ms,rt_rays,flip_mean,relmse,psnr,ssim,reflection_mean_ms,reflection_span_ms,screen_space_idle_frames")
if(NOT header STREQUAL expected)
  message(FATAL_ERROR "${OUT}/bench.csv: header '${header}', expected '${expected}'")
endif()
list(LENGTH lines count)
math(EXPR rows "${count} - 1")
if(rows LESS 8)
  message(FATAL_ERROR "${OUT}/bench.csv: ${rows} rows, expected 3 mode defaults and the quick sweeps")
endif()
foreach(mode hybrid ssr rt)
  if(NOT "${lines}" MATCHES "plaza,${mode},default,,64,48,")
    message(FATAL_ERROR "${OUT}/bench.csv: no default row for ${mode}")
  endif()
endforeach()
# Only the hybrid renders frames as rt (FeedbackSettings::hostGate).
foreach(mode ssr rt)
  if(NOT "${lines}" MATCHES "plaza,${mode},default,,64,48,[^;]*,0(;|$)")
    message(FATAL_ERROR "${OUT}/bench.csv: the ${mode} default row has screen_space_idle_frames other than 0")
  endif()
endforeach()
file(READ ${OUT}/bench.json json)
foreach(key device driver date commit rows)
  string(JSON value ERROR_VARIABLE err GET "${json}" ${key})
  if(err)
    message(FATAL_ERROR "${OUT}/bench.json: no '${key}': ${err}")
  endif()
endforeach()
string(JSON jrows LENGTH "${json}" rows)
if(NOT jrows EQUAL rows)
  message(FATAL_ERROR "${OUT}/bench.json: ${jrows} rows, the CSV has ${rows}")
endif()
bench_require_ran_to_end(${OUT}/bench.json ${rows})
message(STATUS "glint-bench: ${rows} configurations")

# --time-limit: a limit that has passed when the reference is done starts no
# configuration; the run still exits 0 and writes a CSV of its header alone
# and a JSON that says it was cut short of what it planned.
file(REMOVE ${OUT}/limit.csv ${OUT}/limit.json)
execute_process(COMMAND ${BENCH} --validate --scene plaza --quick --size 64x48 --frames 3
                        --reference-max-frames 4 --time-limit 0.001 --out-dir ${OUT}/limit
                        --csv ${OUT}/limit.csv --json ${OUT}/limit.json --plot ${OUT}/limit.png
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glint-bench --time-limit exited with ${rc}")
endif()
bench_require_cut_short_before_start(${OUT}/limit.csv ${OUT}/limit.json ${rows})
