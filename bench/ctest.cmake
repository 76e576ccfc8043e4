# The experiment runner's tests (bench/tests, pytest), included from the top-level CMakeLists
# after enable_testing(). They run the built CLI on tiny synthetic experiments, through a local
# process pool and through a dask.distributed cluster they start on 127.0.0.1.
#
# The interpreter must import pytest (and dask.distributed for the cluster tests, which skip
# without it): the system's python3 has the Debian packages even where another python3 comes
# first on PATH.
set(PSPSLAM_BENCH_PYTHON "" CACHE FILEPATH "python3 that runs bench/tests (needs pytest)")
if(NOT PSPSLAM_BENCH_PYTHON)
  find_program(python_on_path python3 NO_CACHE)
  foreach(candidate IN ITEMS /usr/bin/python3 ${python_on_path})
    if(EXISTS ${candidate})
      execute_process(COMMAND ${candidate} -c "import pytest" RESULT_VARIABLE missing
                      OUTPUT_QUIET ERROR_QUIET)
      if(missing EQUAL 0)
        set(PSPSLAM_BENCH_PYTHON ${candidate} CACHE FILEPATH
            "python3 that runs bench/tests (needs pytest)" FORCE)
        break()
      endif()
    endif()
  endforeach()
endif()

if(PSPSLAM_BENCH_PYTHON)
  add_test(NAME bench_runner
           COMMAND ${CMAKE_COMMAND} -E env PSPSLAM_CLI_PATH=$<TARGET_FILE:pspslam_cli>
                   ${PSPSLAM_BENCH_PYTHON} -m pytest -q -p no:cacheprovider
                   ${CMAKE_CURRENT_LIST_DIR}/tests)
  set_tests_properties(bench_runner PROPERTIES TIMEOUT 600 LABELS bench)
else()
  message(STATUS "bench_runner test not registered: no python3 with pytest (apt install python3-pytest)")
endif()
