# End to end through the command line and examples/embed_walkthrough: a small city, a drive, a pipeline bake of the
# cells it visits, then the example embeds the walkthrough over the database and renders the drive. Run by ctest with
# -DFARFIELD=<binary> -DEXAMPLE=<embed_walkthrough binary> -DWORK=<scratch dir>.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/cli_helpers.cmake)

run_ok(${FARFIELD} gen city --blocks 12 --detail 0 --seed 4 -o ${WORK}/city.glb)
run_ok(${FARFIELD} path street ${WORK}/city.streets.json --frames 20 --fps 5 --seed 4 --car -o ${WORK}/drive.json)
run_ok(${FARFIELD} bake ${WORK}/city.glb --pipeline pvs,near-far,mmi --resolution 128 --pvs-face 32 --pvs-spacing 10
       --path ${WORK}/drive.json -o ${WORK}/imp)
run_ok(${EXAMPLE} ${WORK}/city.glb ${WORK}/imp ${WORK}/drive.json 4 ${WORK}/last.png)
if(NOT LAST_OUT MATCHES "error bound: 4.00 px" OR NOT LAST_OUT MATCHES "layers drawn as impostors [0-9]+ times")
  message(FATAL_ERROR "embed_walkthrough did not report its plan:\n${LAST_OUT}")
endif()
if(NOT EXISTS ${WORK}/last.png)
  message(FATAL_ERROR "embed_walkthrough did not write its frame")
endif()
# With a frame budget, the governor: a budget every frame keeps leaves every frame at full detail; one no frame can
# keep (a microsecond) puts every frame at the coarsest level, the 4 px geometry at half the resolution, which keeps
# twice the 4 px bound (relaxed).
run_ok(${EXAMPLE} ${WORK}/city.glb ${WORK}/imp ${WORK}/drive.json 4 ${WORK}/governed.png 1000)
if(NOT LAST_OUT MATCHES "governor: t_max 1000.00 ms, frames per level 20 0 0 0 0, relaxed 0 of 20")
  message(FATAL_ERROR "embed_walkthrough's governor at a generous budget:\n${LAST_OUT}")
endif()
run_ok(${EXAMPLE} ${WORK}/city.glb ${WORK}/imp ${WORK}/drive.json 4 ${WORK}/governed.png 0.001)
if(NOT LAST_OUT MATCHES "frames per level 0 0 0 0 20, relaxed 20 of 20, measured over t_max 1[0-9]")
  message(FATAL_ERROR "embed_walkthrough's governor at an impossible budget:\n${LAST_OUT}")
endif()
# Sillion's bake is the pipeline's single stage, and says so; the depth-mesh walk reads it through the walkthrough.
run_ok(${FARFIELD} bake ${WORK}/city.glb --technique grid-mesh --resolution 64 --path ${WORK}/drive.json --limit 2
       -o ${WORK}/sillion)
if(NOT LAST_OUT MATCHES "--pipeline near-far,single --layer-mesh grid --station-spacing 0"
   OR NOT LAST_OUT MATCHES "baked \\[near-far,single\\]")
  message(FATAL_ERROR "bake --technique did not say it is the pipeline near-far,single:\n${LAST_OUT}")
endif()
# A database that is not there is a clear error, exit code 2.
execute_process(COMMAND ${EXAMPLE} ${WORK}/city.glb ${WORK}/nothing ${WORK}/drive.json RESULT_VARIABLE rc
                ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "error: .*nothing")
  message(FATAL_ERROR "a missing database: exit code ${rc}, stderr: ${err}")
endif()
