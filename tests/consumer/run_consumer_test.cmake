# ctest driver: install evcorner into a scratch prefix, build the consumer against it,
# and check it finds the golden number of corners in the bundled sample.
# -D BUILD_DIR=... -D SOURCE_DIR=... -D WORK_DIR=... -D EXPECTED=...
file(REMOVE_RECURSE "${WORK_DIR}")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${WORK_DIR}/build"
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/consumer" "${SOURCE_DIR}/data/ecd/shapes_translation/events.txt")
string(STRIP "${out}" out)
if(NOT out STREQUAL "${EXPECTED}")
  message(FATAL_ERROR "consumer found ${out} corners, the golden has ${EXPECTED}")
endif()
message(STATUS "consumer found ${out} corners, as the golden")
