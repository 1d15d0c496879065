# Runs glint-bench --motion (BENCH) small: the plaza's path and the
# mirror-motion scene (its lamp skinned), hybrid defaults only, tiny and short, validation on,
# writing CSV, JSON and plot under OUT. Checks the exit code, the files, the
# CSV header (report.h's kMotionCsvHeader), one row whose motion metrics are
# numbers (the roughness bands may be nan where the image has no such
# surface), the JSON's per-frame FLIP and that it ran to the end.
cmake_policy(SET CMP0054 NEW)
include(${CMAKE_CURRENT_LIST_DIR}/bench_checks.cmake)
file(REMOVE ${OUT}/motion.csv ${OUT}/motion.json ${OUT}/motion.png)
execute_process(COMMAND ${BENCH} --validate --motion --motion-lamp skinned --quick --modes hybrid --sweep-modes "" --size 64x48 --frames 8
                        --reference-max-frames 16 --out-dir ${OUT}
                        --csv ${OUT}/motion.csv --json ${OUT}/motion.json --plot ${OUT}/motion.png
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glint-bench --motion exited with ${rc}")
endif()
foreach(f motion.csv motion.json motion.png)
  if(NOT EXISTS ${OUT}/${f})
    message(FATAL_ERROR "glint-bench --motion did not write ${OUT}/${f}")
  endif()
endforeach()
file(STRINGS ${OUT}/motion.csv lines)
list(GET lines 0 header)
set(expected "scene,mode,param,value,width,height,reflection_ms,flip_still,flip_motion,ghost_energy_1,ghost_energy_4,ghost_energy_16,lag_px,flicker,flip_mirror,flip_glossy,flip_rough,flip_very_rough")
if(NOT header STREQUAL expected)
  message(FATAL_ERROR "${OUT}/motion.csv: header '${header}', expected '${expected}'")
endif()
list(LENGTH lines count)
if(NOT count EQUAL 2)
  message(FATAL_ERROR "${OUT}/motion.csv: ${count} lines, expected a header and the hybrid defaults")
endif()
list(GET lines 1 row)
set(n "[0-9][0-9.e+-]*")
if(NOT row MATCHES "^plaza,hybrid,default,,64,48,${n},${n},${n},${n},${n},${n},${n},${n},")
  message(FATAL_ERROR "${OUT}/motion.csv: '${row}' lacks a time or a motion metric")
endif()
file(READ ${OUT}/motion.json json)
string(JSON frames LENGTH "${json}" rows 0 flip_per_frame)
if(NOT frames EQUAL 4)
  message(FATAL_ERROR "${OUT}/motion.json: ${frames} per-frame FLIP values, expected 4")
endif()
string(JSON lamp GET "${json}" mirror_lamp)
if(NOT lamp STREQUAL "skinned")
  message(FATAL_ERROR "${OUT}/motion.json: mirror_lamp '${lamp}', expected skinned")
endif()
bench_require_ran_to_end(${OUT}/motion.json 1)
