# Run by the build at every build (scenes/CMakeLists.txt), not at configure time: writes OUT from
# IN with the source tree's git commit, so that a run's summary names the commit it was built
# from. configure_file rewrites OUT, and so recompiles it, only when its text changes.
#   -DSOURCE_DIR=... -DIN=... -DOUT=... -DBUILD_TYPE=...
set(CONFORM_GIT_COMMIT "unknown")  # outside a checkout (a release tarball, say)
set(CONFORM_GIT_DIRTY "false")
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} rev-parse --show-toplevel HEAD
                  OUTPUT_VARIABLE lines RESULT_VARIABLE rc ERROR_QUIET
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  string(REPLACE "\n" ";" lines "${lines}")
  list(LENGTH lines n)
  if(rc EQUAL 0 AND n EQUAL 2)
    list(GET lines 0 top)
    list(GET lines 1 commit)
    file(REAL_PATH "${top}" top)
    file(REAL_PATH "${SOURCE_DIR}" src)
    # Only the project's own repository: a source tree unpacked inside another one is not it.
    if(top STREQUAL src)
      set(CONFORM_GIT_COMMIT "${commit}")
      # --no-optional-locks: a build never holds index.lock while the user runs git.
      execute_process(COMMAND ${GIT_EXECUTABLE} --no-optional-locks -C ${SOURCE_DIR} status
                              --porcelain --untracked-files=no
                      OUTPUT_VARIABLE changes RESULT_VARIABLE status_rc ERROR_QUIET
                      OUTPUT_STRIP_TRAILING_WHITESPACE)
      if(NOT status_rc EQUAL 0 OR NOT changes STREQUAL "")
        set(CONFORM_GIT_DIRTY "true")
      endif()
    endif()
  endif()
endif()
set(CONFORM_BUILD_TYPE "${BUILD_TYPE}")
configure_file(${IN} ${OUT} @ONLY)
