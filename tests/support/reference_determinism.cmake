# The reference is deterministic for a seed. Renders it twice
# (RENDER, ARGS without --out) into OUT_A and OUT_B and requires identical
# PNGs, then once with another seed, which must differ (the seed reaches
# the noise).
cmake_policy(SET CMP0054 NEW)
foreach(run "A;0" "B;0" "C;7")
  list(GET run 0 tag)
  list(GET run 1 seed)
  execute_process(COMMAND ${RENDER} ${ARGS} --seed ${seed} --out ${OUT}_${tag}.png RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "glint-render (run ${tag}) exited with ${rc}")
  endif()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}_A.png ${OUT}_B.png RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "two reference renders with seed 0 differ: ${OUT}_A.png ${OUT}_B.png")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}_A.png ${OUT}_C.png RESULT_VARIABLE other)
if(other EQUAL 0)
  message(FATAL_ERROR "seeds 0 and 7 gave the same reference: the seed does not reach the noise")
endif()
