# Writes OUT (a C++ header) with GLINT_BUILD_COMMIT, the source tree's
# `git describe --always --dirty`, rewriting it only when the commit changed
# (so the binaries that include it rebuild only then). Run at every build.
execute_process(COMMAND git -C ${SOURCE_DIR} describe --always --dirty --abbrev=12
                OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(commit STREQUAL "")
  set(commit "unknown")
endif()
set(text "// Generated at build time by cmake/write_commit.cmake.\n#pragma once\n#define GLINT_BUILD_COMMIT \"${commit}\"\n")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
else()
  set(old "")
endif()
if(NOT old STREQUAL text)
  file(WRITE ${OUT} "${text}")
endif()
