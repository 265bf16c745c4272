# Kill-and-resume test of `morphfem search` (ctest search.kill_and_resume_matches_uninterrupted).
# 1. An uninterrupted run writes WORK/whole.
# 2. The same run into WORK/killed is killed with SIGKILL twice (mid-generation of the
#    first experiment's hill climber, then part way through the second experiment's
#    CMA-ES iteration), then started again until it finishes; that session must reuse
#    the evaluations saved before the second kill (optim/search_partial.h).
# 3. Every result file (CSVs, checkpoint.h5, best schedules, validation.csv) must be
#    byte-for-byte identical to the uninterrupted run's.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
# 4 climbers x 40 ms: one generation takes about 160 ms.
set(args search --experiments flat_open,hill_semi --method hill,cmaes --climbers 4 --generations 12
         --fitness synthetic --fidelity 2 --validate-fidelity 8 --eval-delay-ms 40 --no-plot --quiet)

execute_process(COMMAND ${MORPHFEM} ${args} --out ${WORK}/whole RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "uninterrupted run failed (${rc}): ${err}")
endif()

# start_and_kill.sh CSV LINES DELAY EXTRA -- command...: starts the command, waits until CSV
# has at least LINES lines and (unless EXTRA is -) the file EXTRA exists, sleeps DELAY s,
# sends SIGKILL. Fails if the run ended first.
file(WRITE ${WORK}/start_and_kill.sh [=[
csv="$1"; lines="$2"; delay="$3"; extra="$4"; shift 5
"$@" >/dev/null 2>&1 &
pid=$!
tries=0
while [ "$( (wc -l < "$csv") 2>/dev/null || echo 0)" -lt "$lines" ] || { [ "$extra" != - ] && [ ! -e "$extra" ]; }; do
  tries=$((tries + 1))
  if [ "$tries" -gt 6000 ] || ! kill -0 "$pid" 2>/dev/null; then echo "run ended before the kill point"; exit 1; fi
  sleep 0.01
done
sleep "$delay"
if ! kill -KILL "$pid" 2>/dev/null; then echo "run ended before SIGKILL"; exit 1; fi
wait "$pid"
echo "killed with status $?"
]=])
set(killed ${WORK}/killed)
# Kill 1: first experiment, hill climber, when generation 3 is written (CSV header + g = 0..3), 80 ms later.
execute_process(COMMAND sh ${WORK}/start_and_kill.sh ${killed}/flat_open/hill/flat_open.csv 5 0.08 - --
                        ${MORPHFEM} ${args} --out ${killed} RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "first kill failed: ${out}")
endif()
message(STATUS "kill 1: ${out}")
file(STRINGS ${killed}/flat_open/hill/flat_open.csv rows)
list(LENGTH rows n)
if(n GREATER_EQUAL 14)
  message(FATAL_ERROR "the killed run had already finished the experiment (${n} CSV lines)")
endif()
# Kill 2: second experiment, CMA-ES, part way through its first iteration (step 1, 4 x 12
# evaluations, about 2 s): once step 0 is in the CSV (header + g = 0) and an evaluation of
# step 1 is saved in partial_team_0.h5 (step 0's file is removed before its CSV row is written).
execute_process(COMMAND sh ${WORK}/start_and_kill.sh ${killed}/hill_semi/cmaes/hill_semi.csv 2 0.1
                        ${killed}/hill_semi/cmaes/partial_team_0.h5 --
                        ${MORPHFEM} ${args} --out ${killed} RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "second kill failed: ${out}")
endif()
message(STATUS "kill 2: ${out}")
if(EXISTS ${killed}/hill_semi/cmaes/hill_semi.csv)
  file(STRINGS ${killed}/hill_semi/cmaes/hill_semi.csv rows)
  list(LENGTH rows n)
  if(n GREATER 2)
    message(FATAL_ERROR "the killed run had already finished the CMA-ES iteration (${n} CSV lines)")
  endif()
endif()
execute_process(COMMAND ${MORPHFEM} ${args} --out ${killed} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "resumed run failed (${rc}): ${err}")
endif()
# The resumed session took the saved evaluations of the unfinished iteration instead of redoing them.
file(READ ${killed}/summary.json json)
string(JSON n_experiments LENGTH ${json} experiments)
math(EXPR last "${n_experiments} - 1")
set(reused -1)
foreach(i RANGE ${last})
  string(JSON name GET ${json} experiments ${i} experiment)
  string(JSON method GET ${json} experiments ${i} method)
  if(name STREQUAL "hill_semi" AND method STREQUAL "cmaes")
    string(JSON reused GET ${json} experiments ${i} evaluations_reused)
    string(JSON timed GET ${json} experiments ${i} evaluations_timed)
  endif()
endforeach()
if(NOT reused GREATER 0)
  message(FATAL_ERROR "the resumed CMA-ES reused ${reused} saved evaluations, expected some")
endif()
message(STATUS "resume reused ${reused} saved evaluations of the unfinished CMA-ES iteration, evaluated ${timed}")
if(EXISTS ${killed}/hill_semi/cmaes/partial_team_0.h5)
  message(FATAL_ERROR "partial_team_0.h5 was left behind after the step completed")
endif()

file(GLOB_RECURSE files RELATIVE ${WORK}/whole ${WORK}/whole/*/*.csv ${WORK}/whole/*/*.h5 ${WORK}/whole/*/*.yaml)
list(LENGTH files count)
if(count LESS 20)
  message(FATAL_ERROR "expected the result files of 2 experiments x 2 methods, found ${count}: ${files}")
endif()
foreach(f ${files})
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/whole/${f} ${killed}/${f} RESULT_VARIABLE diff)
  if(NOT diff EQUAL 0)
    message(FATAL_ERROR "${f} differs between the uninterrupted and the killed-and-resumed run")
  endif()
endforeach()
message(STATUS "${count} files identical after two SIGKILLs and a resume")
