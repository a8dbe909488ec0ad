# Checks the include direction of the layout (DEVELOPERS.md, "Layout"): every
#   #include "<path>"
# in a .cpp/.hpp under ROOT must start with a prefix its folder may include. Run as
#   cmake -DROOT=<repo> -P tests/check_layering.cmake
# Prints each forbidden include as "forbidden include: <file>:<line>: <path>" and fails.
if(NOT ROOT)
  message(FATAL_ERROR "check_layering: pass -DROOT=<folder>")
endif()

set(core "gdsr/error\\.hpp|gdsr/geometry/|gdsr/body/|gdsr/model/|gdsr/data/|gdsr/io/|gdsr/sim/")
# folder regex (matched on the path relative to ROOT) ; allowed include regex
set(rules
  "^autograd/"             "^autograd/"
  "^nn/"                   "^(autograd|nn)/"
  "^gdsr/error\\.(hpp|cpp)$" "^gdsr/error\\.hpp$"
  "^gdsr/geometry/"        "^(autograd/|gdsr/error\\.hpp|gdsr/geometry/)"
  "^gdsr/body/"            "^gdsr/(error\\.hpp|geometry/|body/)"
  "^gdsr/model/"           "^(autograd/|nn/|gdsr/error\\.hpp|gdsr/geometry/|gdsr/model/)"
  "^gdsr/data/"            "^(autograd/|nn/|gdsr/error\\.hpp|gdsr/geometry/|gdsr/body/|gdsr/model/|gdsr/data/|gdsr/io/)"
  "^gdsr/io/"              "^gdsr/(error\\.hpp|geometry/|body/|io/)"
  "^gdsr/sim/"             "^gdsr/(error\\.hpp|geometry/|body/|io/|sim/)"
  "^gdsr/cli/main\\.cpp$"  "^(gdsr/cli/commands|autograd/runtime)\\.hpp$"
  "^gdsr/cli/"             "^gdsr/(io|cli)/"
  "^train/cmd_"            "^(autograd/|nn/|gdsr/|train/)"
  "^train/"                "^(autograd/|nn/|${core}|train/)"
  "^infer/cmd_"            "^(autograd/|nn/|gdsr/|infer/)"
  "^infer/"                "^(autograd/|nn/|${core}|infer/)"
  "^tests/[^/]*$"          "^tests/support/"
  "^tests/autograd/"       "^(autograd/|tests/support/)"
  "^tests/nn/"             "^(autograd/|nn/|tests/support/)"
  "^tests/gdsr/"           "^(autograd/|nn/|${core}|tests/support/)"
  "^tests/train/"          "^(autograd/|nn/|${core}|train/|tests/support/)"
  "^tests/infer/"          "^(autograd/|nn/|${core}|infer/|tests/support/)"
  "^tests/cli/"            "^(autograd/|nn/|${core}|gdsr/cli/|tests/support/)"
  "^tests/fuzz/"           "^fuzz/"
  "^fuzz/"                 "^(autograd/|nn/|${core}|train/loss_config\\.hpp|fuzz/)"
  "^tests/support/"        "^(autograd/|nn/|${core}|tests/support/)"
  "^bench/"                "^(autograd/|nn/|gdsr/|train/|infer/|tests/support/)"
)

file(GLOB_RECURSE files RELATIVE ${ROOT} ${ROOT}/*.cpp ${ROOT}/*.hpp)
list(FILTER files EXCLUDE REGEX "^(build[^/]*|third_party)/")
list(LENGTH rules nrules)
math(EXPR last "${nrules} - 1")
set(bad 0)
set(checked 0)
foreach(f ${files})
  if(NOT ROOT MATCHES "layering_violation" AND f MATCHES "^tests/support/layering_violation/")
    continue()  # the planted violation is checked by its own test
  endif()
  set(allowed "")
  foreach(i RANGE 0 ${last} 2)
    math(EXPR j "${i} + 1")
    list(GET rules ${i} folder)
    if(f MATCHES "${folder}")
      list(GET rules ${j} allowed)
      break()
    endif()
  endforeach()
  if(allowed STREQUAL "")
    message(STATUS "forbidden include: ${f}: a source file outside the known folders (add a rule)")
    math(EXPR bad "${bad} + 1")
    continue()
  endif()
  file(STRINGS ${ROOT}/${f} lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  foreach(line ${lines})
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]*)\".*" "\\1" inc "${line}")
    math(EXPR checked "${checked} + 1")
    if(NOT inc MATCHES "${allowed}")
      message(STATUS "forbidden include: ${f}: \"${inc}\" (this folder may include ${allowed})")
      math(EXPR bad "${bad} + 1")
    endif()
  endforeach()
endforeach()
if(bad GREATER 0)
  message(FATAL_ERROR "check_layering: ${bad} forbidden include(s)")
endif()
message(STATUS "check_layering: ${checked} includes in ${ROOT} follow the layout")
