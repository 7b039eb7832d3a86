# cmake -DWEB_DIR=... -DOUT_DIR=... -DNPM=... -DNODE=... -P build-web.cmake
# Installs the npm packages from the lock file when needed, then builds with vite into OUT_DIR.
set(stamp ${WEB_DIR}/node_modules/.package-lock.json)
if(NOT EXISTS ${stamp} OR ${WEB_DIR}/package-lock.json IS_NEWER_THAN ${stamp})
  message(STATUS "web: npm ci")
  execute_process(COMMAND ${NPM} ci --no-audit --no-fund WORKING_DIRECTORY ${WEB_DIR} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "web: npm ci failed (${rc})")
  endif()
endif()
execute_process(COMMAND ${NODE} ${WEB_DIR}/node_modules/vite/bin/vite.js build --logLevel warn
                        --outDir ${OUT_DIR} --emptyOutDir
                WORKING_DIRECTORY ${WEB_DIR} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "web: vite build failed (${rc})")
endif()
