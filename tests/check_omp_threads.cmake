# Checks that every OpenMP region of the library asking for a fixed thread count,
# `num_threads(N)`, also honours the OpenMP limit with `if (omp_get_max_threads() > 1)` (or a
# stricter condition containing it); tests/ and bench/ are left out, as they ask for two threads
# on purpose, to test and time the two-thread paths. ctest runs two tests side by side with OMP_NUM_THREADS=1 (scripts/test.sh);
# a region that took two threads anyway had each test's threads spin-waiting for a core: the
# kneel test of tests/gdsr/sim/test_cloth.cpp took 148 s in CI against 35 s on one thread.
# Run as
#   cmake -DROOT=<repo> -P tests/check_omp_threads.cmake
# Prints each offending pragma as "fixed thread count: <file>: <pragma>" and fails.
if(NOT ROOT)
  message(FATAL_ERROR "check_omp_threads: pass -DROOT=<folder>")
endif()
file(GLOB_RECURSE files RELATIVE ${ROOT} ${ROOT}/*.cpp ${ROOT}/*.hpp)
list(FILTER files EXCLUDE REGEX "^(build[^/]*|third_party|tests|bench)/")
set(bad 0)
set(checked 0)
foreach(f ${files})
  file(STRINGS ${ROOT}/${f} lines REGEX "^[ \t]*#[ \t]*pragma[ \t]+omp[ \t].*num_threads[ \t]*\\(")
  foreach(line ${lines})
    math(EXPR checked "${checked} + 1")
    if(NOT line MATCHES "omp_get_max_threads\\(\\) > 1")
      string(STRIP "${line}" line)
      message(STATUS "fixed thread count: ${f}: ${line} (add: if (omp_get_max_threads() > 1))")
      math(EXPR bad "${bad} + 1")
    endif()
  endforeach()
endforeach()
if(bad GREATER 0)
  message(FATAL_ERROR "check_omp_threads: ${bad} region(s) ignore OMP_NUM_THREADS")
endif()
if(checked EQUAL 0)
  message(FATAL_ERROR "check_omp_threads: no num_threads region found under ${ROOT} (wrong folder?)")
endif()
message(STATUS "check_omp_threads: ${checked} fixed-thread-count regions in ${ROOT} honour OMP_NUM_THREADS")
