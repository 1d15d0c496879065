# glint_add_test(<name> SOURCES <files...> [LIBS <targets...>] [LABELS <labels...>] [GPU])
#
# One doctest executable registered as one ctest test. GPU tests carry the
# label "gpu" and run serially: lavapipe already uses both cores.
function(glint_add_test name)
  cmake_parse_arguments(ARG "GPU" "" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE glint_test_main ${ARG_LIBS} glint_warnings)
  add_test(NAME ${name} COMMAND ${name} --no-intro --reporters=console)
  set(labels ${ARG_LABELS})
  if(ARG_GPU)
    list(APPEND labels gpu)
    set_tests_properties(${name} PROPERTIES RUN_SERIAL ON)
  endif()
  if(labels)
    set_tests_properties(${name} PROPERTIES LABELS "${labels}")
  endif()
endfunction()
