# Writes OUTPUT with `#define PSPSLAM_GIT_REVISION "<git describe --always --dirty>"` ("unknown"
# outside a git checkout), touching it only when the revision changed, so that every build (not
# only a configure) stamps the binary with the revision it was built from and an unchanged one
# recompiles nothing. Run by the pspslam_git_revision target (src/pspslam/core/CMakeLists.txt).
set(revision "unknown")
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(COMMAND ${GIT_EXECUTABLE} describe --always --dirty
                  WORKING_DIRECTORY ${SOURCE_DIR}
                  OUTPUT_VARIABLE describe OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE describe_status ERROR_QUIET)
  if(describe_status EQUAL 0)
    set(revision "${describe}")
  endif()
endif()
set(content "#define PSPSLAM_GIT_REVISION \"${revision}\"\n")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
endif()
if(NOT "${old}" STREQUAL "${content}")
  file(WRITE "${OUTPUT}" "${content}")
endif()
