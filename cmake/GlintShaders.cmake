# glint_add_shaders(<target> ROOT <dir> OUTPUT_DIR <dir> SOURCES <files...>)
#
# Compiles each GLSL file to <OUTPUT_DIR>/<relative path>.spv with
# glslangValidator (Vulkan 1.2 target so ray tracing stages and SPIR-V 1.5
# features are available), tracks #include dependencies through the depfile
# glslangValidator writes, and validates the result with spirv-val. A shader
# error fails the build with glslang's "ERROR: <file>:<line>: ..." line.
# spirv-val checks scalar block layout rules: the device enables
# scalarBlockLayout and shared structs use it (glint/shared.h).
function(glint_add_shaders target)
  cmake_parse_arguments(ARG "" "ROOT;OUTPUT_DIR" "SOURCES;INCLUDE_DIRS" ${ARGN})
  set(outputs)
  foreach(src ${ARG_SOURCES})
    file(RELATIVE_PATH rel ${ARG_ROOT} ${src})
    set(spv ${ARG_OUTPUT_DIR}/${rel}.spv)
    get_filename_component(spv_dir ${spv} DIRECTORY)
    set(include_flags)
    foreach(inc ${ARG_INCLUDE_DIRS})
      list(APPEND include_flags -I${inc})
    endforeach()
    add_custom_command(
      OUTPUT ${spv}
      COMMAND ${CMAKE_COMMAND} -E make_directory ${spv_dir}
      COMMAND ${GLSLANG_VALIDATOR} --quiet --target-env vulkan1.2 -g ${include_flags}
              --depfile ${spv}.d -o ${spv} ${src}
      COMMAND ${SPIRV_VAL} --target-env vulkan1.2 --scalar-block-layout ${spv}
      DEPENDS ${src}
      DEPFILE ${spv}.d
      COMMENT "GLSL ${rel}"
      VERBATIM)
    list(APPEND outputs ${spv})
  endforeach()
  add_custom_target(${target} ALL DEPENDS ${outputs})
endfunction()
