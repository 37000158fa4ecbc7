# cmake -DPROGRAM=... -DRUN_DIR=... -P train_and_eval.cmake: trains CartPoleGoal-v0 (state
# observations) for 8,192 env steps into a fresh RUN_DIR, checks the run folder, then evaluates
# it with the program's eval, expecting its "mean" line.
file(REMOVE_RECURSE ${RUN_DIR})
execute_process(COMMAND ${PROGRAM} train CartPoleGoal-v0 --set obs_mode=state --steps 8192
                        --num-envs 4 --eval-episodes 2 --quiet --out ${RUN_DIR}
                RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "train exited ${result}:\n${out}\n${err}")
endif()
foreach(file config.json progress.csv summary.json final.mp4 curve.png)
  if(NOT EXISTS ${RUN_DIR}/${file})
    message(FATAL_ERROR "the run folder ${RUN_DIR} has no ${file}:\n${out}")
  endif()
endforeach()
execute_process(COMMAND ${PROGRAM} eval ${RUN_DIR} --episodes 2
                RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result EQUAL 0 OR NOT out MATCHES "mean")
  message(FATAL_ERROR "eval exited ${result}:\n${out}\n${err}")
endif()
message(STATUS "${out}")
