# examples/embed_terrain end to end: a small fractal written as a tile cache, then a flight drawn with LOD-sprite
# wholly on the CDLOD terrain paged from it (sprite frames, keyframes, pages), the last frame written; run again, it
# reads the cache it wrote; a terrain it cannot read is an error. Run by ctest with -DEXAMPLE=<embed_terrain binary>
# -DWORK=<scratch dir>.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/cli_helpers.cmake)

run_ok(${EXAMPLE} fractal:513:7:relief=1200 ${WORK}/t.tiles 60 ${WORK}/last.png)
if(NOT LAST_OUT MATCHES "wrote the tile cache" OR NOT LAST_OUT MATCHES "60 frames: [1-9][0-9]* sprite frames")
  message(FATAL_ERROR "embed_terrain did not draw sprite frames from the cache it wrote:\n${LAST_OUT}")
endif()
if(NOT LAST_OUT MATCHES "pages: [1-9][0-9]* held at most")
  message(FATAL_ERROR "embed_terrain held no page:\n${LAST_OUT}")
endif()
if(NOT EXISTS ${WORK}/last.png)
  message(FATAL_ERROR "embed_terrain did not write its frame")
endif()
run_ok(${EXAMPLE} fractal:513:7:relief=1200 ${WORK}/t.tiles 20)
if(LAST_OUT MATCHES "wrote the tile cache" OR NOT LAST_OUT MATCHES "20 frames:")
  message(FATAL_ERROR "embed_terrain did not read the cache it had written:\n${LAST_OUT}")
endif()
execute_process(COMMAND ${EXAMPLE} ${WORK}/no-such-dem.tif ${WORK}/none.tiles RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "no-such-dem.tif")
  message(FATAL_ERROR "embed_terrain on a missing DEM: exit ${rc}, stderr: ${err}")
endif()
