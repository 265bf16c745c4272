# Kill-and-resume test of `morphfem search` (ctest search.kill_and_resume_matches_uninterrupted).
# 1. An uninterrupted run writes WORK/whole.
# 2. The same run into WORK/killed is killed with SIGKILL twice (mid-generation of the
#    first experiment's hill climber, then during the second experiment's CMA-ES),
#    then started again until it finishes.
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

# start_and_kill.sh CSV LINES DELAY -- command...: starts the command, waits until CSV has
# at least LINES lines, sleeps DELAY s, sends SIGKILL. Fails if the run ended first.
file(WRITE ${WORK}/start_and_kill.sh [=[
csv="$1"; lines="$2"; delay="$3"; shift 4
"$@" >/dev/null 2>&1 &
pid=$!
tries=0
while [ "$( (wc -l < "$csv") 2>/dev/null || echo 0)" -lt "$lines" ]; do
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
execute_process(COMMAND sh ${WORK}/start_and_kill.sh ${killed}/flat_open/hill/flat_open.csv 5 0.08 --
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
# Kill 2: second experiment, CMA-ES, after its second step (evaluations 0..13 written).
execute_process(COMMAND sh ${WORK}/start_and_kill.sh ${killed}/hill_semi/cmaes/hill_semi.csv 6 0.05 --
                        ${MORPHFEM} ${args} --out ${killed} RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "second kill failed: ${out}")
endif()
message(STATUS "kill 2: ${out}")
execute_process(COMMAND ${MORPHFEM} ${args} --out ${killed} RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "resumed run failed (${rc}): ${err}")
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
