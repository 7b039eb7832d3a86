# Each bad invocation of rp-model must print exactly one line on stderr and exit with status 2.
set(cases
  "--robot;nosuchrobot;fk;--q;0,0,0,0,0,0"
  "--robot;puma560;fk;--q;0,0,0"
  "--robot;puma560;fk;--q;0,0,x,0,0,0"
  "--robot;puma560;fk"
  "--robot;puma560;dance;--q;0,0,0,0,0,0"
  "--robot;puma560;ik;--pose;1,0,0,5,0,1,0,0,0,0,1,0,0,0,0,1"
  "--robot;puma560;ik;--pose;1,2,3"
  "--robot;missing.urdf;fk;--q;0"
  "--robot;puma560;--tip;link3;fk;--q;0,0,0,0,0,0"
  "fk;--q;0,0,0,0,0,0")
foreach(args IN LISTS cases)
  string(REPLACE ";" " " shown "${args}")
  separate_arguments(argv UNIX_COMMAND "${shown}")
  execute_process(COMMAND ${PROGRAM} ${argv} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(STRIP "${err}" err)
  string(FIND "${err}" "\n" newline)
  if(NOT rc EQUAL 2 OR NOT newline EQUAL -1 OR NOT err MATCHES "^rp-model: ")
    message(FATAL_ERROR "rp-model ${shown}: status ${rc}, stderr '${err}'")
  endif()
  message("rp-model ${shown} -> ${err}")
endforeach()
