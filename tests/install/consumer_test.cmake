# cmake -DBUILD_DIR=... -DCONSUMER_DIR=... -DWORK_DIR=... -P consumer_test.cmake
# Installs BUILD_DIR into WORK_DIR/prefix, builds CONSUMER_DIR against it with find_package, runs
# the consumer, the installed `pixelgym list` and `pixelgym train --config NAME --print-config`
# (the installed recipes, found by name), and fails with the step's output when a step
# fails or prints something other than expected. PIXELGYM_ASSET_PATH is unset throughout: the
# installed code must find its assets from where it was installed.
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
unset(ENV{PIXELGYM_ASSET_PATH})

function(step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "${name} failed (${result}):\n${ARGN}\n${out}\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

step("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(installed include/pixelgym/envs/registry.h include/pixelgym/trainer/training_run.h
                  share/pixelgym/assets/cartpole bin/pixelgym bin/pixelgym-train)
  if(NOT EXISTS ${prefix}/${installed})
    message(FATAL_ERROR "cmake --install did not install ${installed} under ${prefix}")
  endif()
endforeach()
# Every header installed includes only installed headers, each by the project's prefix
# (pixelgym/envs/registry.h, as an outside project includes it), and the renderer's private ones (the
# OpenGL declarations) are not installed.
if(EXISTS ${prefix}/include/pixelgym/render/gl.h)
  message(FATAL_ERROR "cmake --install installed the private render/gl.h")
endif()
file(GLOB_RECURSE headers RELATIVE ${prefix}/include/pixelgym ${prefix}/include/pixelgym/*.h)
foreach(header ${headers})
  file(STRINGS ${prefix}/include/pixelgym/${header} includes REGEX "^#include \"")
  foreach(line ${includes})
    string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" included "${line}")
    if(NOT included MATCHES "^pixelgym/")
      message(FATAL_ERROR "the installed ${header} includes \"${included}\", not by the "
                          "project's prefix (\"pixelgym/${included}\")")
    endif()
    if(NOT EXISTS ${prefix}/include/${included})
      message(FATAL_ERROR "the installed ${header} includes ${included}, which is not installed")
    endif()
  endforeach()
endforeach()
# The targets put include/ on a consumer's path, not include/pixelgym/ (whose envs/, render/, ...
# would shadow an outside project's own folders of those names).
file(GLOB_RECURSE targets_files ${prefix}/pixelgymTargets.cmake)
file(STRINGS "${targets_files}" include_lines REGEX "INTERFACE_INCLUDE_DIRECTORIES")
foreach(line ${include_lines})
  if(line MATCHES "include/pixelgym")
    message(FATAL_ERROR "an installed target puts include/pixelgym on the consumer's path:\n${line}")
  endif()
endforeach()
file(GLOB_RECURSE config ${prefix}/pixelgymConfig.cmake)
if(NOT config)
  message(FATAL_ERROR "cmake --install did not install pixelgymConfig.cmake under ${prefix}")
endif()

set(every_header ${WORK_DIR}/every_header.cc)
file(WRITE ${every_header} "// Every installed header, included as an outside project does.\n")
foreach(header ${headers})
  file(APPEND ${every_header} "#include <pixelgym/${header}>\n")
endforeach()
step("configuring the consumer" ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/build
     -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix} -DEVERY_HEADER=${every_header})
step("building the consumer" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
step("running the consumer" ${WORK_DIR}/build/consumer)
message(STATUS "consumer:\n${step_output}")
if(NOT step_output MATCHES "assets: ${prefix}/share/pixelgym/assets\n")
  message(FATAL_ERROR "the installed engine did not use the installed assets under ${prefix}")
endif()
if(NOT step_output MATCHES "consumer ran to the end\n$")
  message(FATAL_ERROR "the consumer did not run to its end")
endif()

# An Algorithm written outside the tree trains through the installed run: a new run of 400 env
# steps, then a resume from its checkpoint to 600.
step("running own_algorithm" ${WORK_DIR}/build/own_algorithm ${WORK_DIR}/own_run)
message(STATUS "own_algorithm:\n${step_output}")
if(NOT step_output MATCHES "own algorithm trained: 8 rows, last best_return [-0-9.e+]+, evaluation return_mean [0-9.e+]+\n"
   OR NOT step_output MATCHES "own algorithm resumed to 600 env steps\n"
   OR NOT step_output MATCHES "own algorithm ran to the end\n$")
  message(FATAL_ERROR "own_algorithm did not train and resume through the installed run:\n${step_output}")
endif()
foreach(written config.json progress.csv summary.json ckpt-000012.pgck)
  if(NOT EXISTS ${WORK_DIR}/own_run/${written})
    message(FATAL_ERROR "own_algorithm's run folder has no ${written}")
  endif()
endforeach()

step("the installed pixelgym list" ${prefix}/bin/pixelgym list)
if(NOT step_output MATCHES "CartPoleSwingup-v0")
  message(FATAL_ERROR "the installed `pixelgym list` did not list CartPoleSwingup-v0:\n${step_output}")
endif()
message(STATUS "the installed pixelgym list: ${step_output}")

# The trainer's recipes are installed, and the installed tool finds them by name from where it was
# installed (its bin/'s share/pixelgym/configs), not from the source tree it was built from.
foreach(recipe ppo/swingup.json ppo/action_repeat_8.json drqv2/cartpole.json)
  if(NOT EXISTS ${prefix}/share/pixelgym/configs/${recipe})
    message(FATAL_ERROR "cmake --install did not install the recipe configs/${recipe}")
  endif()
endforeach()
file(REAL_PATH ${prefix} real_prefix)
step("the installed pixelgym train --list-configs" ${prefix}/bin/pixelgym train --list-configs)
string(FIND "${step_output}" "ppo (--algo ppo), ${real_prefix}/share/pixelgym/configs/ppo:\n"
       listed)
if(listed EQUAL -1)
  message(FATAL_ERROR "the installed `pixelgym train --list-configs` did not list the installed "
                      "recipes of ${real_prefix}/share/pixelgym/configs/ppo:\n${step_output}")
endif()
step("the installed pixelgym train --config swingup --print-config" ${prefix}/bin/pixelgym train
     CartPoleSwingup-v0 --config swingup --print-config)
if(NOT step_output MATCHES "\"gamma\": 0.95" OR NOT step_output MATCHES "\"num_steps\": 64")
  message(FATAL_ERROR "the installed `pixelgym train --config swingup` did not take the "
                      "swingup recipe's settings:\n${step_output}")
endif()
message(STATUS "the installed pixelgym train --config swingup: resolved")
