# `morphfem run SCENE --set KEY=VALUE`: the assignments reach the scene (end time and
# output directory in summary.json), and a misspelt option is refused (exit 2, named).
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${MORPHFEM} run ${SCENE} --set solver.end_time=0.5 --set output.directory=${WORK}/out
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "morphfem run --set failed (${rc}):\n${out}\n${err}")
endif()
file(READ ${WORK}/out/summary.json json)
string(JSON end GET ${json} end_time_reached)
execute_process(COMMAND awk "BEGIN { exit (${end} == 0.5) ? 0 : 1 }" RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "--set solver.end_time=0.5 ran to ${end}")
endif()
execute_process(COMMAND ${MORPHFEM} run ${SCENE} --sett solver.end_time=0.5
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "unknown option '--sett'")
  message(FATAL_ERROR "a misspelt option gave exit ${rc}:\n${out}\n${err}")
endif()
execute_process(COMMAND ${MORPHFEM} run ${SCENE} --set solver.end_tim=0.5
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "end_tim")
  message(FATAL_ERROR "a misspelt scene key gave exit ${rc}:\n${out}\n${err}")
endif()
