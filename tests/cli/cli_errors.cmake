# Every bad input to the command-line tool gives "error: ..." on stderr and exit code 2, never a crash.
# Run by ctest with -DFARFIELD=<binary> -DWORK=<scratch dir>.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/cli_helpers.cmake)
file(WRITE ${WORK}/garbage.glb "glTF this is not a binary gltf")
file(WRITE ${WORK}/notes.xyz "nothing")
file(WRITE ${WORK}/bad.png "PNG truncated: not an image")
file(WRITE ${WORK}/garbage.osm.pbf "garbage")
file(WRITE ${WORK}/badpath.json "{\"kind\": \"street\"")

expect_error("no-such-file.obj" info ${WORK}/no-such-file.obj)
expect_error("garbage.glb" info ${WORK}/garbage.glb)
expect_error("notes.xyz" info ${WORK}/notes.xyz)
expect_error("builtin:nope" info builtin:nope)
expect_error("--eye" render builtin:cube --eye 1,2 -o ${WORK}/x.png)
expect_error("--size" render builtin:cube --eye 3,3,3 --size 12by4 -o ${WORK}/x.png)
expect_error("coincide" render builtin:cube --eye 0,0,0 --at 0,0,0 -o ${WORK}/x.png)
expect_error("bad.png" diff ${WORK}/bad.png ${WORK}/bad.png)
expect_error("missing.png" diff ${WORK}/missing.png ${WORK}/bad.png)
expect_error("frobnicate" frobnicate)
expect_error("garbage.osm.pbf" import osm ${WORK}/garbage.osm.pbf -o ${WORK}/x.glb)
expect_error("badpath.json" import cityjson ${WORK}/badpath.json -o ${WORK}/x.glb)
expect_error("badpath.json" path street ${WORK}/badpath.json -o ${WORK}/p.json)
expect_error("--blocks" gen city --blocks 5 -o ${WORK}/c.glb)
expect_error("no-such-dem.tif" gen city --blocks 10 --terrain ${WORK}/no-such-dem.tif -o ${WORK}/c.glb)
expect_error("2^n + 1" gen city --blocks 10 --terrain fractal:12 -o ${WORK}/c.glb)
expect_error("--terrain-scale" gen city --blocks 10 --terrain fractal:33 --terrain-scale -1 -o ${WORK}/c.glb)
expect_error("--hill" gen city --blocks 10 --hill --terrain fractal:33 -o ${WORK}/c.glb)
expect_error("badpath.json" walk builtin:cubes --path ${WORK}/badpath.json --mode full)
expect_error("nopath.json" bench builtin:cubes --path ${WORK}/nopath.json --modes full -o ${WORK}/b)
expect_error("--view-min" path views builtin:cubes --view-min 1,2 --view-max 3,4,5 -o ${WORK}/v.json)
expect_error("--view-min/--view-max" path views builtin:cubes --view-min 1,2,3 -o ${WORK}/v.json)
expect_error("profile.json" place builtin:cubes --profile ${WORK}/profile.json -o ${WORK}/placed)
expect_error("--tmax" bench builtin:cubes --path ${WORK}/nopath.json --tmax -3 -o ${WORK}/b)
expect_error("--budget-coarsens: needs a budget" crowd bench --budget-coarsens --skinned-lod 0.1 -o ${WORK}/crowd)
expect_error("--compare-skinning: compares the palette" crowd bench --compare-skinning --palette-skinning -o ${WORK}/crowd)
# A mode option no mode of the run reads (a typo) is refused, after the modes are made.
execute_process(COMMAND ${FARFIELD} path orbit builtin:cubes --frames 2 -o ${WORK}/orbit.json RESULT_VARIABLE rc
                OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "farfield path orbit failed: ${rc}")
endif()
expect_error("--mode-option erorr_px" bench builtin:cubes --path ${WORK}/orbit.json --modes full,culled
             --mode-option erorr_px=2 -o ${WORK}/b)
expect_error("--pipeline" bake builtin:cubes --pipeline pvs,bogus -o ${WORK}/imp)
expect_error("--pipeline" bake builtin:cubes --pipeline mmi -o ${WORK}/imp)
expect_error("--online" bake builtin:cubes --pipeline pvs,near-far,mmi --online pvs -o ${WORK}/imp)
expect_error("--layer-mesh" bake builtin:cubes --pipeline pvs,near-far,mmi --layer-mesh voxels -o ${WORK}/imp)
expect_error("--online" bake builtin:cubes --online mmi -o ${WORK}/imp)
expect_error("the order is pvs, near-far, single, mmi" bake builtin:cubes --pipeline pvs,near-far,mmi,single
             -o ${WORK}/imp)
expect_error("single needs near-far" bake builtin:cubes --pipeline pvs,single -o ${WORK}/imp)
# --technique is Sillion's cell impostor, the pipeline near-far,single: one mesh kind per store, no contradictions.
expect_error("Bake twice" bake builtin:cubes --technique both -o ${WORK}/imp)
expect_error("--technique" bake builtin:cubes --technique depth-mesh --pipeline near-far,single -o ${WORK}/imp)
expect_error("--layer-mesh" bake builtin:cubes --technique grid-mesh --layer-mesh depth-mesh -o ${WORK}/imp)
expect_error("--station-spacing" bake builtin:cubes --technique depth-mesh --station-spacing 5 -o ${WORK}/imp)

# Numbers beyond the types the options are read into: errors naming the option, not conversions.
expect_error("--sweep-frames: frame count: 1.0000000000000001e+300 is out of range" terrain bench fractal:33
             --sweep-frames 75,1e300 -o ${WORK}/terrain)
expect_error("--sweep-frames: frame count: 75.5 is not a whole number" terrain bench fractal:33 --sweep-frames 75.5
             -o ${WORK}/terrain)
expect_error("fractal:99999999999: SIZE" terrain info fractal:99999999999)
expect_error("no-such-dem.tif: DEM file not found" terrain export ${WORK}/no-such-dem.tif -o ${WORK}/e.tif)
expect_error("/no-such-dir/e.tif" terrain export fractal:33 -o /no-such-dir/e.tif)
expect_error("--gpu-budget-mb: must be positive" terrain tiles fractal:65 --block 16 --frames 4 --render
             --gpu-budget-mb 0 -o ${WORK}/tiles)
expect_error("--prefetch-frames: must be 0 or more" terrain tiles fractal:65 --block 16 --frames 4 --render
             --prefetch-frames -1 -o ${WORK}/tiles)
expect_error("a GPU budget of 0.01 MiB cannot hold a tile" terrain tiles fractal:65 --block 16 --frames 4 --render
             --gpu-budget-mb 0.01 -o ${WORK}/tiles)
