# ctest Consumer.InstallsBuildsAndRuns: install the build into a fresh prefix, bake the Cornell
# box with the installed gi-bake, configure and build tests/consumer against the prefix alone
# (find_package(gi)), run it. Any missing header, library, exported dependency or tool fails
# one of the steps.
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... [-DCXX=... -DLAUNCHER=... -DGENERATOR=...
#         -DLINK_FLAGS=...] -P run.cmake
# LINK_FLAGS: what an instrumented build's static libraries need at the consumer's link
# (their sanitizer runtimes, tools/configure-sanitized.sh); empty for a regular build.
foreach(_v BUILD_DIR SOURCE_DIR WORK_DIR)
  if(NOT DEFINED ${_v})
    message(FATAL_ERROR "run.cmake needs -D${_v}=...")
  endif()
endforeach()

function(step)
  string(REPLACE ";" " " _shown "${ARGN}")
  message(STATUS "consumer: ${_shown}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "consumer: failed (${_rc}): ${_shown}")
  endif()
endfunction()

set(_prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${_prefix})

# The installed tool bakes the bundle the consumer loads.
step(${_prefix}/bin/gi-bake --scene ${SOURCE_DIR}/assets/cornell_box.gltf --preset preview
     --out ${WORK_DIR}/cornell_box.gibake)

set(_configure ${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/consumer -B ${WORK_DIR}/build
    -DCMAKE_PREFIX_PATH=${_prefix} -DCMAKE_BUILD_TYPE=Release)
if(GENERATOR)
  list(APPEND _configure -G ${GENERATOR})
endif()
if(CXX)
  list(APPEND _configure -DCMAKE_CXX_COMPILER=${CXX})
endif()
if(LAUNCHER)
  list(APPEND _configure -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
if(LINK_FLAGS)
  list(APPEND _configure "-DCMAKE_EXE_LINKER_FLAGS=${LINK_FLAGS}")
endif()
step(${_configure})
step(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
step(${WORK_DIR}/build/consumer ${SOURCE_DIR}/assets/cornell_box.gltf ${WORK_DIR}/cornell_box.gibake)
