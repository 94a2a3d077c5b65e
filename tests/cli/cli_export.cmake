# farfield export end to end: a small city written as .glb alone, with a pipeline store's impostors and with a
# placement's layered impostors, and as a 3D Tiles tileset; every .glb written goes through the Khronos glTF validator
# (tools/gltf-validator, installed by scripts/install-deps.sh) and must have 0 errors. Bad input gives "error: ...".
# Run by ctest with -DFARFIELD=<binary> -DWORK=<scratch dir> -DSOURCE_DIR=<repository>; prints SKIPPED (a skipped
# test) only when node or the validator is absent.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/cli_helpers.cmake)

find_program(NODE node)
set(VALIDATOR ${SOURCE_DIR}/tools/gltf-validator/validate.js)
if(NOT NODE OR NOT EXISTS ${SOURCE_DIR}/tools/gltf-validator/node_modules/gltf-validator/package.json)
  message(STATUS "SKIPPED: node or the glTF validator is missing (run scripts/install-deps.sh)")
  return()
endif()

# validate(FILES...): the validator must find 0 errors in every file.
function(validate)
  execute_process(COMMAND ${NODE} ${VALIDATOR} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "glTF validator: exit code ${rc}\n${out}\n${err}")
  endif()
  list(LENGTH ARGN n)
  message(STATUS "validator: ${n} files, 0 errors")
endfunction()

run_ok(${FARFIELD} gen city --blocks 10 --detail 0 --seed 4 -o ${WORK}/city.glb)
run_ok(${FARFIELD} path street ${WORK}/city.streets.json --frames 40 --fps 2 --seed 4 --car -o ${WORK}/drive.json)

# The scene alone.
run_ok(${FARFIELD} export ${WORK}/city.glb -o ${WORK}/scene.glb)
validate(${WORK}/scene.glb)

# A pipeline store (single mesh and MMI layers per cell): textured depth meshes grouped per street cell.
run_ok(${FARFIELD} bake ${WORK}/city.glb --pipeline pvs,near-far,single,mmi --resolution 96 --pvs-face 32
       --pvs-spacing 10 --path ${WORK}/drive.json -o ${WORK}/pipeline.imp)
run_ok(${FARFIELD} export ${WORK}/city.glb --impostors ${WORK}/pipeline.imp -o ${WORK}/pipeline.glb)
if(NOT LAST_OUT MATCHES "impostors \\(pipeline store [^)]*\\): [1-9][0-9]* in [1-9][0-9]* view regions")
  message(FATAL_ERROR "export --impostors (pipeline) wrote no impostors:\n${LAST_OUT}")
endif()
validate(${WORK}/pipeline.glb)

# A placement (layered impostors, alpha-tested quads) with a hand-made cost profile, so that placement has problem
# views on any machine.
file(WRITE ${WORK}/profile.json [=[{"format": "farfield-cost-profile", "version": 1,
 "model": {"base_ms": 1.0, "ms_per_mtriangle": 400.0, "ms_per_draw": 0.25, "ms_per_mpixel": 0.0, "samples": 0,
           "rms_error_ms": 0.0, "r2": 1.0},
 "safety_factor": 1.0, "width": 128, "height": 128, "fov_y_deg": 45.0, "renderer": "hand-made", "validation": {}}]=])
run_ok(${FARFIELD} place ${WORK}/city.glb --profile ${WORK}/profile.json --tmax 2.5 --error-px 2 --size 128x128
       --fov 45 --visibility-face 32 --max-texture 128 --levels 5 --distance-steps 3 --texel-px 2
       --around ${WORK}/drive.json --margin 20 -o ${WORK}/city.place)
run_ok(${FARFIELD} export ${WORK}/city.glb --impostors ${WORK}/city.place -o ${WORK}/placed.glb)
if(NOT LAST_OUT MATCHES "impostors \\(placement [^)]*\\): [1-9][0-9]* in [1-9][0-9]* view regions")
  message(FATAL_ERROR "export --impostors (placement) wrote no impostors:\n${LAST_OUT}")
endif()
validate(${WORK}/placed.glb)

# The 3D Tiles tileset: every tile's content validated; the exporter has run the tileset checks itself.
run_ok(${FARFIELD} export ${WORK}/city.glb --tiles ${WORK}/tiles --error-px 2 --size 640x480 --fov 60
       --leaf-objects 3 --texels 128)
if(NOT LAST_OUT MATCHES "textured heightfield impostors" OR NOT EXISTS ${WORK}/tiles/tileset.json)
  message(FATAL_ERROR "export --tiles:\n${LAST_OUT}")
endif()
file(GLOB tiles ${WORK}/tiles/tiles/*.glb)
list(LENGTH tiles n_tiles)
if(n_tiles LESS 3)
  message(FATAL_ERROR "export --tiles wrote ${n_tiles} tiles")
endif()
validate(${tiles})

# expect_in_glb(FILE TEXT...): the glb's JSON chunk holds each text.
function(expect_in_glb file)
  file(STRINGS ${file} text)
  foreach(t ${ARGN})
    string(FIND "${text}" "${t}" pos)
    if(pos EQUAL -1)
      message(FATAL_ERROR "${file} lacks ${t}")
    endif()
  endforeach()
endfunction()
expect_in_glb(${WORK}/pipeline.glb "\"name\":\"impostors\"" "\"kind\":\"street cell\"" "\"kind\":\"textured depth mesh\""
              "\"alphaMode\":\"MASK\"" "KHR_materials_unlit" "\"creation_camera\"")
expect_in_glb(${WORK}/placed.glb "\"kind\":\"conservative problem view\"" "\"kind\":\"layered impostor\""
              "\"alphaMode\":\"MASK\"" "\"error_angle_rad\"")

# Bad input.
file(MAKE_DIRECTORY ${WORK}/not_a_database)
expect_error("is not an impostor database" export ${WORK}/city.glb --impostors ${WORK}/not_a_database
             -o ${WORK}/x.glb)
run_ok(${FARFIELD} gen city --blocks 12 --detail 0 --seed 5 -o ${WORK}/other.glb)
expect_error("not this scene's database" export ${WORK}/other.glb --impostors ${WORK}/pipeline.imp -o ${WORK}/x.glb)
file(WRITE ${WORK}/a_file "x")
expect_error("cannot be written" export ${WORK}/city.glb --tiles ${WORK}/a_file/tiles)
expect_error("a_file" export ${WORK}/city.glb -o ${WORK}/a_file/x.glb)
expect_error("either -o FILE.glb or --tiles DIR" export ${WORK}/city.glb)
