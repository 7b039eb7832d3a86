# Script for the install_consumer test (see CMakeLists.txt next to it).
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE} -B ${WORK_DIR}/build -G ${GENERATOR}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
execute_process(COMMAND ${WORK_DIR}/build/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "consumer exited with ${rc}")
endif()
if(NOT "${out}" MATCHES "consumer: end-effector position 0.5 0.25 1")
  message(FATAL_ERROR "the consumer did not print its end-effector position")
endif()
# The installed copy on its own: the prefix moved out of the build tree, a program run from it
# without LD_LIBRARY_PATH and with the build and source trees hidden serves the installed front
# end, or the folder RP_WEB_ROOT names (check-relocated.sh says what it checks).
execute_process(COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/check-relocated.sh ${prefix} ${BUILD_DIR} ${SOURCE_DIR}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the relocated install check failed (${rc})")
endif()
