# The package as an engine uses it (examples/embed): installs this build
# into OUT/prefix, configures and builds the example against it with
# find_package(Glint), then
# - checks that the graph-only program does not need the Vulkan loader and
#   runs it (declare, compile, verify);
# - runs the example from OUT/prefix/bin, where it must find Glint's shaders
#   relative to itself (GLINT_SHADER_DIR unset), renders 4 frames with
#   validation and writes a PNG.
# With SUBDIRECTORY=ON: configures the example with add_subdirectory(Glint's
# source tree) instead and builds the graph-only program, which must give
# the same targets.
# Inputs: BUILD_DIR SOURCE_DIR OUT GENERATOR CMAKE_CXX_COMPILER BUILD_TYPE [FLAGS] [SUBDIRECTORY]
cmake_policy(SET CMP0054 NEW)
cmake_policy(SET CMP0057 NEW)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "${command}: exited with ${rc}\n${out}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${OUT})
set(example ${SOURCE_DIR}/examples/embed)
set(configure ${CMAKE_COMMAND} -S ${example} -B ${OUT}/build -G ${GENERATOR} -DCMAKE_BUILD_TYPE=${BUILD_TYPE}
    -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER}
    "-DCMAKE_CXX_FLAGS=${FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${FLAGS}")

if(SUBDIRECTORY)
  run(${configure} -DGLINT_SOURCE_DIR=${SOURCE_DIR})
  run(${CMAKE_COMMAND} --build ${OUT}/build --target glint-embed-graph)
  run(${OUT}/build/glint-embed-graph)
  message(STATUS "add_subdirectory: glint-embed-graph built and ran")
  return()
endif()

run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${OUT}/prefix)
foreach(file include/glint/graph/graph.h include/glint/graph/verify.h include/glint/passes/reflection_frame.h
             include/glint/packing.h share/glint/shaders/noise/blue_noise.bin
             share/glint/shaders/composite/composite.comp.spv lib/cmake/Glint/GlintConfig.cmake)
  if(NOT EXISTS ${OUT}/prefix/${file})
    message(FATAL_ERROR "the install has no ${file}")
  endif()
endforeach()

run(${configure} -DCMAKE_PREFIX_PATH=${OUT}/prefix)
run(${CMAKE_COMMAND} --build ${OUT}/build)

# Glint::graph needs no Vulkan loader.
run(readelf -d ${OUT}/build/glint-embed-graph)
if(run_output MATCHES "libvulkan")
  message(FATAL_ERROR "glint-embed-graph needs the Vulkan loader:\n${run_output}")
endif()
run(${OUT}/build/glint-embed-graph)
if(NOT run_output MATCHES "verifier: ok")
  message(FATAL_ERROR "glint-embed-graph:\n${run_output}")
endif()

# Installed beside Glint, the example finds the shaders relative to itself.
file(COPY ${OUT}/build/glint-embed DESTINATION ${OUT}/prefix/bin)
run(${CMAKE_COMMAND} -E env --unset=GLINT_SHADER_DIR ${OUT}/prefix/bin/glint-embed ${OUT}/embed.png 96x64)
message(STATUS "${run_output}")
if(NOT run_output MATCHES "shaders from ${OUT}/prefix/share/glint/shaders")
  message(FATAL_ERROR "glint-embed did not take the installed shaders:\n${run_output}")
endif()
file(SIZE ${OUT}/embed.png bytes)
if(bytes LESS 1000)
  message(FATAL_ERROR "${OUT}/embed.png: ${bytes} bytes")
endif()
