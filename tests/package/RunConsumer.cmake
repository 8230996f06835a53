# Builds and runs the consumer project (consumer/) against Weft; run by the package.* tests.
#
#   cmake -DMODE=install|subdirectory -DCONSUMER_DIR=<dir> -DWORK_DIR=<dir>
#         -DGENERATOR=<gen> [-DMAKE_PROGRAM=<path>] -DCXX_COMPILER=<path>
#         [-DWEFT_BUILD_DIR=<build tree> -DINSTALL_LIBDIR=lib -DWITH_RENDER=ON]   (install)
#         [-DWEFT_SOURCE_DIR=<source tree>]                                       (subdirectory)
#         -P RunConsumer.cmake
#
# install:      cmake --install <build tree> --prefix <WORK_DIR>/prefix, checks what was
#               installed, then configures the consumer with CMAKE_PREFIX_PATH=<prefix>.
# subdirectory: configures the consumer with WEFT_SOURCE_DIR, so it does add_subdirectory().
# Both then build the consumer (Release, 2 jobs) and run it; any failing step fails the test.
#
# The consumer's build directory is kept between runs (its cache is not), so a second run
# recompiles only what changed; the install prefix is always rebuilt from nothing, so a file that
# is no longer installed cannot linger there.
cmake_minimum_required(VERSION 3.22)

foreach(var MODE CONSUMER_DIR WORK_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "RunConsumer.cmake: -D${var}=... is required")
  endif()
endforeach()

if(NOT WITH_RENDER)
  set(WITH_RENDER OFF)
endif()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc COMMAND_ECHO STDOUT)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "RunConsumer.cmake: step failed (${rc})")
  endif()
endfunction()

set(consumer_build ${WORK_DIR}/consumer-build)
set(configure_args
  -S ${CONSUMER_DIR} -B ${consumer_build} -G ${GENERATOR}
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX_COMPILER})
if(MAKE_PROGRAM)
  list(APPEND configure_args -DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM})
endif()
# A fresh cache every time: no package location or option remembered from an earlier run.
file(REMOVE ${consumer_build}/CMakeCache.txt)

if(MODE STREQUAL "install")
  foreach(var WEFT_BUILD_DIR INSTALL_LIBDIR)
    if(NOT DEFINED ${var})
      message(FATAL_ERROR "RunConsumer.cmake: MODE=install needs -D${var}=...")
    endif()
  endforeach()
  set(prefix ${WORK_DIR}/prefix)
  file(REMOVE_RECURSE ${prefix})
  run(${CMAKE_COMMAND} --install ${WEFT_BUILD_DIR} --prefix ${prefix})

  # What a user of the package relies on is there; what is internal is not.
  set(cmakedir ${prefix}/${INSTALL_LIBDIR}/cmake/Weft)
  foreach(file ${cmakedir}/WeftConfig.cmake ${cmakedir}/WeftConfigVersion.cmake
               ${prefix}/include/weft/Weft.h ${prefix}/include/weft/engine/World.h
               ${prefix}/include/weft/Math.h ${prefix}/include/weft/threading/TaskSystem.h)
    if(NOT EXISTS ${file})
      message(FATAL_ERROR "RunConsumer.cmake: not installed: ${file}")
    endif()
  endforeach()
  file(GLOB export_files ${cmakedir}/weft-*-targets*.cmake)
  foreach(file IN LISTS export_files)
    file(READ ${file} text)
    if(text MATCHES "weft_[a-z]+_internal|weft::scenes|weft_scenes")
      message(FATAL_ERROR "RunConsumer.cmake: ${file} exports a test-only target "
                          "(${CMAKE_MATCH_0}); only the modules belong in the package")
    endif()
  endforeach()
  if(EXISTS ${prefix}/include/weft/scenes)
    message(FATAL_ERROR "RunConsumer.cmake: the scenes headers were installed; scenes is internal")
  endif()

  list(APPEND configure_args -DCMAKE_PREFIX_PATH=${prefix} -DWEFT_SOURCE_DIR=
                             -DWEFT_CONSUMER_RENDER=${WITH_RENDER})
elseif(MODE STREQUAL "subdirectory")
  if(NOT WEFT_SOURCE_DIR)
    message(FATAL_ERROR "RunConsumer.cmake: MODE=subdirectory needs -DWEFT_SOURCE_DIR=...")
  endif()
  # Only the libraries: tests, benchmarks, examples and the renderer would triple the build time
  # and are not what a game embeds.
  list(APPEND configure_args -DWEFT_SOURCE_DIR=${WEFT_SOURCE_DIR} -DWEFT_CONSUMER_RENDER=OFF
    -DWEFT_BUILD_TESTS=OFF -DWEFT_BUILD_BENCH=OFF -DWEFT_BUILD_EXAMPLES=OFF
    -DWEFT_BUILD_RENDER=OFF)
else()
  message(FATAL_ERROR "RunConsumer.cmake: MODE must be install or subdirectory, not '${MODE}'")
endif()

run(${CMAKE_COMMAND} ${configure_args})
run(${CMAKE_COMMAND} --build ${consumer_build} --parallel 2)

set(exe ${consumer_build}/weft-consumer)
if(NOT EXISTS ${exe})
  set(exe ${consumer_build}/Release/weft-consumer)  # multi-configuration generators
endif()
execute_process(COMMAND ${exe} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0 OR NOT out MATCHES "weft-consumer: ok")
  message(FATAL_ERROR "RunConsumer.cmake: weft-consumer failed (${rc})")
endif()
