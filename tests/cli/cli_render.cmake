# End to end: render the built-in scene, check the outputs exist, diff a frame with itself and with another view,
# and print scene info. Run by ctest with -DFARFIELD=<binary> -DWORK=<scratch dir>.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/cli_helpers.cmake)

run_ok(${FARFIELD} render builtin:cubes --eye 18,-22,14 --at 0,0,1 --fov 55 --size 160x120 -o ${WORK}/a.png
       --depth ${WORK}/a.pfm --ids ${WORK}/a_ids.png)
foreach(f a.png a.pfm a_ids.png)
  if(NOT EXISTS ${WORK}/${f})
    message(FATAL_ERROR "render did not write ${f}")
  endif()
endforeach()
if(NOT LAST_OUT MATCHES "triangles: +[1-9]")
  message(FATAL_ERROR "render did not report triangles:\n${LAST_OUT}")
endif()
if(NOT LAST_OUT MATCHES "gpu ms:")
  message(FATAL_ERROR "render did not report GPU time:\n${LAST_OUT}")
endif()

run_ok(${FARFIELD} diff ${WORK}/a.png ${WORK}/a.png --json)
if(NOT LAST_OUT MATCHES "\"identical\": true")
  message(FATAL_ERROR "a frame differs from itself:\n${LAST_OUT}")
endif()

run_ok(${FARFIELD} render builtin:cubes --eye 20,-20,14 --at 0,0,1 --fov 55 --size 160x120 -o ${WORK}/b.png)
run_ok(${FARFIELD} diff ${WORK}/a.png ${WORK}/b.png --json --heatmap ${WORK}/d.png)
if(NOT LAST_OUT MATCHES "\"identical\": false")
  message(FATAL_ERROR "two different views compare identical:\n${LAST_OUT}")
endif()
if(NOT EXISTS ${WORK}/d.png)
  message(FATAL_ERROR "diff did not write the heat map")
endif()

run_ok(${FARFIELD} info builtin:cubes)
if(NOT LAST_OUT MATCHES "objects: +2[0-9]")
  message(FATAL_ERROR "info builtin:cubes should list 26 objects (ground + 25 boxes):\n${LAST_OUT}")
endif()
