# `morphfem run --resume` after SIGKILL, on 2 MPI ranks (ctest app.run_kill_and_resume):
# 1. an uninterrupted run of a sliding block (inertia, contact, friction) writes WORK/whole;
# 2. the same run into WORK/killed checkpoints every step and is killed with SIGKILL
#    (its whole process group: mpirun and both ranks) once its first checkpoint exists;
# 3. `--resume` on 1 rank is refused (exit 2, names the rank count); on 2 ranks it finishes;
# 4. steps, Newton iterations, the final displacement and the gait speed in summary.json
#    match the uninterrupted run's (relative 1e-10), and the result has every step.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
# The resume tests' sliding block (tests/sim/scenes/slide.yaml), larger and run longer,
# so that the kill comes well before the end.
set(scene ${SCENE} --set geometry.lx=0.04 --set geometry.ly=0.04 --set geometry.mesh_size=0.005
          --set solver.end_time=1.5 --set solver.max_step=0.01 --set output.every=10)
set(mpi ${MPIEXEC} -n 2)
execute_process(COMMAND ${mpi} ${MORPHFEM} run ${scene} --set output.directory=${WORK}/whole
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "uninterrupted run failed (${rc}):\n${out}\n${err}")
endif()

# start_and_kill.sh FILE -- command...: starts the command in its own process group, waits
# until FILE exists, sends SIGKILL to the group. Fails if the run ended first.
file(WRITE ${WORK}/start_and_kill.sh [=[
file="$1"; shift 2
setsid "$@" >/dev/null 2>&1 &
pid=$!
tries=0
while [ ! -e "$file" ]; do
  tries=$((tries + 1))
  if [ "$tries" -gt 30000 ] || ! kill -0 "$pid" 2>/dev/null; then echo "run ended before the kill point"; exit 1; fi
  sleep 0.01
done
if ! kill -9 -$pid 2>/dev/null; then echo "run ended before SIGKILL"; exit 1; fi
wait "$pid"
echo "killed with status $?"
]=])
set(killed ${WORK}/killed)
execute_process(COMMAND sh ${WORK}/start_and_kill.sh ${killed}.partial/checkpoint.h5 --
                        ${mpi} ${MORPHFEM} run ${scene} --set output.directory=${killed}
                        --set output.checkpoint_s=1e-9
                RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "kill failed: ${out}")
endif()
message(STATUS "${out}")
if(EXISTS ${killed}/summary.json)
  message(FATAL_ERROR "the killed run had already finished")
endif()

execute_process(COMMAND ${MORPHFEM} run ${scene} --set output.directory=${killed} --resume
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "mpirun -n 2")
  message(FATAL_ERROR "resuming on 1 rank gave exit ${rc}:\n${out}\n${err}")
endif()
execute_process(COMMAND ${mpi} ${MORPHFEM} run ${scene} --set output.directory=${killed} --resume
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "resumed at t = ")
  message(FATAL_ERROR "resumed run failed (${rc}):\n${out}\n${err}")
endif()
message(STATUS "${out}")

file(READ ${WORK}/whole/summary.json a)
file(READ ${killed}/summary.json b)
string(JSON resumed GET ${b} resumed_at_s)
execute_process(COMMAND awk "BEGIN { exit (${resumed} > 0 && ${resumed} < 1.5) ? 0 : 1 }" RESULT_VARIABLE mid)
if(NOT mid EQUAL 0)
  message(FATAL_ERROR "resumed_at_s = ${resumed}: not a resume from the middle of the run")
endif()
foreach(key steps newton_its)
  string(JSON va GET ${a} ${key})
  string(JSON vb GET ${b} ${key})
  if(NOT va EQUAL vb)
    message(FATAL_ERROR "${key}: ${va} uninterrupted, ${vb} killed and resumed")
  endif()
endforeach()
foreach(key max_displacement_m end_time_reached)
  string(JSON va GET ${a} ${key})
  string(JSON vb GET ${b} ${key})
  execute_process(COMMAND awk "BEGIN { d = (${va} - ${vb}) / ${va}; if (d < 0) d = -d; exit (d <= 1e-10) ? 0 : 1 }"
                  RESULT_VARIABLE close)
  if(NOT close EQUAL 0)
    message(FATAL_ERROR "${key}: ${va} uninterrupted, ${vb} killed and resumed")
  endif()
endforeach()
file(READ ${WORK}/whole/slide.xdmf xa)
file(READ ${killed}/slide.xdmf xb)
string(REGEX MATCHALL "<Time Value=\"[^\"]*\"" ta "${xa}")
string(REGEX MATCHALL "<Time Value=\"[^\"]*\"" tb "${xb}")
if(NOT ta STREQUAL tb)
  message(FATAL_ERROR "the resumed result's steps differ from the uninterrupted run's")
endif()
list(LENGTH ta n)
message(STATUS "killed at a checkpoint, resumed: ${n} steps, summary identical")
