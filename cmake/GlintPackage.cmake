# glint_add_library(<target> EXPORT_NAME <name> SOURCES <files...>)
#
# One of Glint's libraries: static unless BUILD_SHARED_LIBS, its headers
# included as "glint/<folder>/<file>.h" from the source tree while building
# and from <prefix>/include once installed, known as Glint::<name> both
# inside this build (for add_subdirectory users) and in the installed
# package (find_package(Glint)), and installed into the GlintTargets export.
function(glint_add_library target)
  cmake_parse_arguments(ARG "" "EXPORT_NAME" "SOURCES" ${ARGN})
  add_library(${target} ${ARG_SOURCES})
  add_library(Glint::${ARG_EXPORT_NAME} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_EXPORT_NAME} OUTPUT_NAME ${target}
                                             POSITION_INDEPENDENT_CODE ON)
  # The shared GLSL/C++ headers (glint/packing.h, glint/*_shared.h) sit in
  # shaders/include in the source tree and beside the C++ headers once
  # installed.
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
                                              $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/shaders/include>
                                              $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} PRIVATE $<BUILD_INTERFACE:glint_warnings>)
  if(GLINT_INSTALL)
    install(TARGETS ${target} EXPORT GlintTargets
            ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
            LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
            RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endfunction()

# The package: headers, SPIR-V and blue noise, the export and the config
# file. Called once from the top level after every library is declared.
function(glint_install_package)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/glint/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/glint
          FILES_MATCHING PATTERN "*.h")
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/shaders/include/glint/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/glint
          FILES_MATCHING PATTERN "*.h")
  # The compiled shaders and the blue noise beside them; the GLSL includes
  # too, for an engine's own shaders that share Glint's packing.
  install(DIRECTORY ${GLINT_SHADER_OUTPUT_DIR}/ DESTINATION ${GLINT_INSTALL_SHADER_DIR}
          FILES_MATCHING PATTERN "*.spv" PATTERN "*.bin")
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/shaders/include/glint/ DESTINATION ${GLINT_INSTALL_SHADER_DIR}/include/glint
          FILES_MATCHING PATTERN "*.glsl" PATTERN "*.h")

  set(config_dir ${CMAKE_INSTALL_LIBDIR}/cmake/Glint)
  install(EXPORT GlintTargets NAMESPACE Glint:: DESTINATION ${config_dir})
  include(CMakePackageConfigHelpers)
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/GlintConfig.cmake.in
                                ${PROJECT_BINARY_DIR}/GlintConfig.cmake INSTALL_DESTINATION ${config_dir}
                                PATH_VARS GLINT_INSTALL_SHADER_DIR)
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/GlintConfigVersion.cmake COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/GlintConfig.cmake ${PROJECT_BINARY_DIR}/GlintConfigVersion.cmake
          DESTINATION ${config_dir})
endfunction()
