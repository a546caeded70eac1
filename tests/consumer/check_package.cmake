# Installs the immerse build tree BUILD into a fresh prefix under WORK, builds tests/consumer against it with
# find_package(immerse) and runs two steps of a capsule; then configures the same consumer with add_subdirectory of
# the source tree SOURCE (configure only: the build is the one above). Fails on any error.
#   cmake -DSOURCE=... -DBUILD=... -DWORK=... -DBUILD_TYPE=... -DCXX_FLAGS=... -DLINKER_FLAGS=... -P check_package.cmake
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK})
set(prefix ${WORK}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD} --prefix ${prefix})
foreach(f bin/immerse include/immerse/simulation/Simulation.hpp lib/cmake/immerse/immerseConfig.cmake
        share/immerse/scenarios/capsule_shear_quick.toml)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "the installed tree lacks ${f}")
  endif()
endforeach()

set(flags -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_CXX_FLAGS_${BUILD_TYPE_UPPER}=${CXX_FLAGS}
          -DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS})
run(${CMAKE_COMMAND} -S ${SOURCE}/tests/consumer -B ${WORK}/installed -DCMAKE_PREFIX_PATH=${prefix} ${flags})
run(${CMAKE_COMMAND} --build ${WORK}/installed)
run(${WORK}/installed/capsule_two_steps ${prefix}/share/immerse/scenarios)
message(STATUS "consumer of the installed package: ${last_output}")
if(NOT last_output MATCHES "^step 2 ")
  message(FATAL_ERROR "the consumer did not take two steps: ${last_output}")
endif()
# The installed program finds the installed scenarios.
run(${prefix}/bin/immerse scenarios)
if(NOT last_output MATCHES "share/immerse/scenarios")
  message(FATAL_ERROR "the installed program lists other scenarios: ${last_output}")
endif()

run(${CMAKE_COMMAND} -S ${SOURCE}/tests/consumer -B ${WORK}/subdirectory -DIMMERSE_SOURCE=${SOURCE} ${flags})
file(REMOVE_RECURSE ${WORK})
