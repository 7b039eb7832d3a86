# The temporary folder every test gets as TMPDIR (tests/CMakeLists.txt): MODE=setup empties and
# creates DIR; MODE=check removes DIR and fails, naming each one, if the tests left files or
# folders in it.
if(MODE STREQUAL "setup")
  file(REMOVE_RECURSE "${DIR}")
  file(MAKE_DIRECTORY "${DIR}")
  return()
endif()
file(GLOB_RECURSE left LIST_DIRECTORIES true RELATIVE "${DIR}" "${DIR}/*")
file(REMOVE_RECURSE "${DIR}")
if(left)
  list(SORT left)
  list(LENGTH left count)
  string(REPLACE ";" "\n  " listing "${left}")
  message(FATAL_ERROR "tests left ${count} files or folders in their temporary folder ${DIR} (now removed):\n"
                      "  ${listing}\n(each test must remove its temporary files, also when it fails)")
endif()
message(STATUS "no files left in ${DIR} (removed)")
