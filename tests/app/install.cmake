# `cmake --install`: the installed program finds its examples and scripts in
# PREFIX/share/morphfem from any working directory, without the source tree's paths.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/elsewhere)
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${WORK}/prefix
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${rc}):\n${out}\n${err}")
endif()
set(installed ${WORK}/prefix/bin/morphfem)
execute_process(COMMAND ${installed} --help WORKING_DIRECTORY ${WORK}/elsewhere
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "examples, scripts and data: ${WORK}/prefix/share/morphfem")
  message(FATAL_ERROR "the installed program does not look in PREFIX/share/morphfem (${rc}):\n${out}\n${err}")
endif()
# A robot case's template (examples/voxel/inch_flat.yaml) read from the installed copy.
execute_process(COMMAND ${installed} robot scene --case inch_flat --preset lattice-mechanics
                WORKING_DIRECTORY ${WORK}/elsewhere RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "template ${WORK}/prefix/share/morphfem/examples/voxel/inch_flat.yaml")
  message(FATAL_ERROR "robot scene from the installed program (${rc}):\n${out}\n${err}")
endif()
# MORPHFEM_DATA_DIR names another copy.
execute_process(COMMAND ${CMAKE_COMMAND} -E env MORPHFEM_DATA_DIR=${WORK}/nowhere ${installed} robot scene --case inch_flat
                WORKING_DIRECTORY ${WORK}/elsewhere RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "${WORK}/nowhere/examples/")
  message(FATAL_ERROR "MORPHFEM_DATA_DIR was not used (${rc}):\n${out}\n${err}")
endif()
