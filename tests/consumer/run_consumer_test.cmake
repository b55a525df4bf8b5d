# ctest driver: install evcorner into a scratch prefix, build two consumers against it and
# check each finds the golden number of corners in the bundled sample:
#   tests/consumer       find_package(evcorner), evcorner::evcorner, an io reader
#   tests/consumer/core  find_package(evcorner COMPONENTS core) with PNG, PkgConfig and
#                        fmt disabled: the detectors need none of them
# The consumers get the build's compiler and flags (sanitizer flags given in
# CMAKE_CXX_FLAGS must reach the consumers too, or they cannot link the library).
# -D BUILD_DIR=... -D SOURCE_DIR=... -D WORK_DIR=... -D EXPECTED=...
# [-D CXX_COMPILER=... -D CXX_FLAGS=... -D LINKER_FLAGS=...]
cmake_minimum_required(VERSION 3.22)
file(REMOVE_RECURSE "${WORK_DIR}")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")

# Only public headers are installed: no test oracles, no internals.
file(GLOB_RECURSE installed RELATIVE "${WORK_DIR}/prefix/include" "${WORK_DIR}/prefix/include/*")
foreach(h IN LISTS installed)
  if(h MATCHES "/naive/|prophesee_header")
    message(FATAL_ERROR "installed a header that is not public: ${h}")
  endif()
endforeach()
if(NOT "evcorner/evcorner.hpp" IN_LIST installed)
  message(FATAL_ERROR "the umbrella header evcorner/evcorner.hpp is not installed")
endif()
list(LENGTH installed n_installed)
message(STATUS "${n_installed} headers installed")

set(common -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
if(CXX_COMPILER)
  list(APPEND common -DCMAKE_CXX_COMPILER=${CXX_COMPILER})
endif()
list(APPEND common "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}")

function(check_consumer name src extra)
  run(${CMAKE_COMMAND} -S "${src}" -B "${WORK_DIR}/${name}" ${common} ${extra})
  run(${CMAKE_COMMAND} --build "${WORK_DIR}/${name}")
  run("${WORK_DIR}/${name}/${name}" "${SOURCE_DIR}/data/ecd/shapes_translation/events.txt")
  string(STRIP "${out}" out)
  if(NOT out STREQUAL "${EXPECTED}")
    message(FATAL_ERROR "${name} found ${out} corners, the golden has ${EXPECTED}")
  endif()
  message(STATUS "${name} found ${out} corners, as the golden")
endfunction()
check_consumer(consumer "${SOURCE_DIR}/tests/consumer" "")
check_consumer(core_consumer "${SOURCE_DIR}/tests/consumer/core"
               "-DCMAKE_DISABLE_FIND_PACKAGE_PNG=ON;-DCMAKE_DISABLE_FIND_PACKAGE_PkgConfig=ON;-DCMAKE_DISABLE_FIND_PACKAGE_fmt=ON;-DCMAKE_DISABLE_FIND_PACKAGE_HDF5=ON")
