# farfield view as a script: bad arguments and bad databases give "error: ..." naming the input and exit code 2 (never
# a crash), and a scripted replay writes its screenshots and recorded path and exits 0. The window needs a display
# (ctest runs under xvfb-run, see the Makefile); without one only the checks made before the window opens run.
# Run by ctest with -DFARFIELD=<binary> -DSOURCE_DIR=<repository> -DWORK=<scratch dir>.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/cli_helpers.cmake)

execute_process(COMMAND ${FARFIELD} path orbit builtin:cubes --frames 3 -o ${WORK}/orbit.json RESULT_VARIABLE rc
                OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "farfield path orbit failed: ${rc}")
endif()
set(script --replay ${WORK}/orbit.json --screenshot-at 0,2 -o ${WORK}/shots --exit --size 160x120)

# Before the window: arguments, the scene, the camera path.
expect_error("--size" view builtin:cubes --size 12by4 --replay ${WORK}/orbit.json --exit)
expect_error("--screenshot-at" view builtin:cubes --replay ${WORK}/orbit.json --screenshot-at 1,x -o ${WORK}/s --exit)
expect_error("--exit" view builtin:cubes --exit)
expect_error("--path/--replay" view builtin:cubes --path ${WORK}/orbit.json --replay ${WORK}/orbit.json)
expect_error("no-such-scene.glb" view ${WORK}/no-such-scene.glb ${script})
expect_error("nopath.json" view builtin:cubes --replay ${WORK}/nopath.json --exit)
expect_error("--terrain-scale" view builtin:cubes --terrain fractal:129:5 --terrain-scale 0 ${script})
expect_error("no-such-model.glb" view builtin:cubes --crowd 10 --crowd-models ${WORK}/no-such-model.glb ${script})
expect_error("--crowd-models" view builtin:cubes --crowd 10 --crowd-models a.glb,b.glb,c.glb ${script})
expect_error("--crowd-error-px" view builtin:cubes --crowd 10 --crowd-error-px 0 ${script})
# The shared CesiumMan is real data beside the repository (../shared/data, or $ENV{FF_SHARED_DATA} as for the C++
# tests). Without it its crowd's frame is not checked; the argument checks, which only look for the file, take a
# stand-in. The built-in figures (no --crowd-models) need no file and are always checked.
set(shared_data ${SOURCE_DIR}/../shared/data)
if(NOT "$ENV{FF_SHARED_DATA}" STREQUAL "")
  set(shared_data $ENV{FF_SHARED_DATA})
endif()
set(man ${shared_data}/models/CesiumMan.glb)
set(model_arg ${man})
if(NOT EXISTS ${man})
  set(model_arg ${WORK}/stand-in.glb)
  file(WRITE ${model_arg} "")
endif()
expect_error("--crowd-error-px" view builtin:cubes --crowd 10 --crowd-models ${model_arg} --crowd-error-px 0 ${script})

if(NOT DEFINED ENV{DISPLAY})
  message(STATUS "skipped: no DISPLAY for the window checks (run under xvfb-run)")
  return()
endif()

# Bad databases: a missing directory, one without an index, a cut index, a garbled placement index.
expect_error("missing.imp" view builtin:cubes --impostors ${WORK}/missing.imp ${script})
file(MAKE_DIRECTORY ${WORK}/empty.imp)
expect_error("empty.imp" view builtin:cubes --impostors ${WORK}/empty.imp ${script})
file(MAKE_DIRECTORY ${WORK}/cut.imp)
file(WRITE ${WORK}/cut.imp/index.json "{\"format\": \"farfield-impostors\", \"version\": 3, \"gen")
expect_error("cut.imp/index.json" view builtin:cubes --impostors ${WORK}/cut.imp ${script})
file(MAKE_DIRECTORY ${WORK}/bad.place)
file(WRITE ${WORK}/bad.place/placement.json "{\"format\": \"farfield-placement\"}")
expect_error("bad.place/placement.json" view builtin:cubes --impostors ${WORK}/bad.place ${script})
expect_error("--mode mmi" view builtin:cubes --mode mmi ${script})

# A scripted replay: screenshots of the frame and of the window, the cameras recorded, exit code 0.
execute_process(COMMAND ${FARFIELD} view builtin:cubes --mode culled ${script} --record ${WORK}/recorded.json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "farfield view (scripted) failed: ${rc}\nstdout: ${out}\nstderr: ${err}")
endif()
foreach(f shots/frame_0.png shots/window_0.png shots/frame_2.png shots/window_2.png recorded.json)
  if(NOT EXISTS ${WORK}/${f})
    message(FATAL_ERROR "farfield view (scripted) did not write ${f}")
  endif()
endforeach()
if(EXISTS ${WORK}/shots/frame_1.png)
  message(FATAL_ERROR "farfield view wrote frame_1.png, which --screenshot-at did not ask for")
endif()

# A city on a terrain, the terrain drawn under it (LOD-sprite over CDLOD keyframes on the GPU, the default) in culled:
# the frame differs from the city alone; a wrong vertical scale is refused (the city's ground would not lie on the
# terrain).
set(terrain fractal:129:5:relief=300)
run_ok(${FARFIELD} gen city --blocks 12 --seed 3 --detail 0 --terrain ${terrain} --terrain-scale 0.5
       -o ${WORK}/tc.glb)
run_ok(${FARFIELD} path flyover ${WORK}/tc.glb --frames 3 --altitude 150 -o ${WORK}/tc_fly.json)
set(tc_script --mode culled --replay ${WORK}/tc_fly.json --screenshot-at 0 --exit --size 160x120)
run_ok(${FARFIELD} view ${WORK}/tc.glb ${tc_script} -o ${WORK}/tc_alone)
run_ok(${FARFIELD} view ${WORK}/tc.glb ${tc_script} -o ${WORK}/tc_terrain --terrain ${terrain} --terrain-scale 0.5)
run_ok(${FARFIELD} diff ${WORK}/tc_alone/frame_0.png ${WORK}/tc_terrain/frame_0.png)
if(LAST_OUT MATCHES "identical")
  message(FATAL_ERROR "farfield view --terrain drew the same frame as without the terrain:\n${LAST_OUT}")
endif()
# The same terrain drawn by the other techniques (CDLOD at 1 px on the GPU, LOD-sprite over the quadtree LOD on the
# CPU): a terrain is drawn too.
foreach(technique high-gpu lod-sprite)
  run_ok(${FARFIELD} view ${WORK}/tc.glb ${tc_script} -o ${WORK}/tc_terrain_${technique} --terrain ${terrain}
         --terrain-scale 0.5 --terrain-technique ${technique})
  run_ok(${FARFIELD} diff ${WORK}/tc_alone/frame_0.png ${WORK}/tc_terrain_${technique}/frame_0.png)
  if(LAST_OUT MATCHES "identical")
    message(FATAL_ERROR "farfield view --terrain-technique ${technique} drew the same frame as without the terrain:\n${LAST_OUT}")
  endif()
endforeach()
expect_error("--terrain-technique" view ${WORK}/tc.glb ${tc_script} -o ${WORK}/tc_bad --terrain ${terrain}
             --terrain-scale 0.5 --terrain-technique clipmap)
expect_error("gen city --terrain" view ${WORK}/tc.glb ${tc_script} -o ${WORK}/tc_bad --terrain ${terrain}
             --terrain-scale 2)

# A crowd on the city's sidewalks, drawn over the mode's frame: the frame differs from the city alone where agents
# stand, with the built-in figures (the default: what a clone without ../shared has) and with the shared CesiumMan
# where it is present; a scene without a street graph is refused naming --crowd.
run_ok(${FARFIELD} gen city --blocks 12 --seed 3 --detail 0 -o ${WORK}/cc.glb)
run_ok(${FARFIELD} path street ${WORK}/cc.streets.json --frames 3 -o ${WORK}/cc_walk.json)
set(cc_script --mode culled --replay ${WORK}/cc_walk.json --screenshot-at 2 --exit --size 160x120)
run_ok(${FARFIELD} view ${WORK}/cc.glb ${cc_script} -o ${WORK}/cc_alone)
run_ok(${FARFIELD} view ${WORK}/cc.glb ${cc_script} -o ${WORK}/cc_builtin --crowd 400 --crowd-ms 5)
run_ok(${FARFIELD} diff ${WORK}/cc_alone/frame_2.png ${WORK}/cc_builtin/frame_2.png)
if(LAST_OUT MATCHES "identical")
  message(FATAL_ERROR "farfield view --crowd (built-in figures) drew the same frame as without the crowd:\n${LAST_OUT}")
endif()
# The same crowd on the GPU (--crowd-gpu, with its budget in time and levels of detail): agents drawn.
run_ok(${FARFIELD} view ${WORK}/cc.glb ${cc_script} -o ${WORK}/cc_gpu --crowd 400 --crowd-gpu --crowd-ms 5
       --crowd-lod-px 0.5)
run_ok(${FARFIELD} diff ${WORK}/cc_alone/frame_2.png ${WORK}/cc_gpu/frame_2.png)
if(LAST_OUT MATCHES "identical")
  message(FATAL_ERROR "farfield view --crowd-gpu drew the same frame as without the crowd:\n${LAST_OUT}")
endif()
if(EXISTS ${man})
  run_ok(${FARFIELD} view ${WORK}/cc.glb ${cc_script} -o ${WORK}/cc_crowd --crowd 400 --crowd-models ${man}
         --crowd-ms 5)
  run_ok(${FARFIELD} diff ${WORK}/cc_alone/frame_2.png ${WORK}/cc_crowd/frame_2.png)
  if(LAST_OUT MATCHES "identical")
    message(FATAL_ERROR "farfield view --crowd drew the same frame as without the crowd:\n${LAST_OUT}")
  endif()
else()
  message(STATUS "not checked: the shared CesiumMan's crowd frame, which needs ../shared/data/models/CesiumMan.glb "
                 "(real data beside the repository; absent in this checkout: no ${man})")
endif()
expect_error("--crowd: needs the city's street graph" view builtin:cubes ${script} --crowd 10)
