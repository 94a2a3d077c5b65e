# farfield calibrate's fill term by default: on for the placed walkthrough's frames (--visibility-cache), off with
# --no-fill-term and without a cache; the profile says which (validation.fill_term).
# Run by ctest with -DFARFIELD=<binary> -DWORK=<scratch dir>.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/cli_helpers.cmake)

run_ok(${FARFIELD} gen city --blocks 10 --detail 0 --seed 4 -o ${WORK}/city.glb)
run_ok(${FARFIELD} path street ${WORK}/city.streets.json --frames 20 --fps 2 --seed 4 --car -o ${WORK}/drive.json)
run_ok(${FARFIELD} place ${WORK}/city.glb -o ${WORK}/visibility --size 64x64 --fov 45 --around ${WORK}/drive.json
       --margin 10 --visibility-face 16 --visibility-cache ${WORK}/vis.bin --visibility-only)

# fill_term_of(PROFILE VAR): the profile's validation.fill_term (ON or OFF).
function(fill_term_of profile var)
  file(READ ${profile} json)
  string(JSON value GET "${json}" validation fill_term)
  set(${var} ${value} PARENT_SCOPE)
endfunction()

set(small --size 64x64 --fov 45 --views 8 --fit-views 8 --repeats 1 --layered-samples 0)
set(cache --visibility-cache ${WORK}/vis.bin)
foreach(case "cache;ON;${cache}" "cache-off;OFF;${cache};--no-fill-term" "no-cache;OFF" "no-cache-on;ON;--fill-term")
  list(GET case 0 name)
  list(GET case 1 want)
  set(options "")
  list(LENGTH case n)
  if(n GREATER 2)
    list(SUBLIST case 2 -1 options)
  endif()
  run_ok(${FARFIELD} calibrate ${WORK}/city.glb -o ${WORK}/${name}.json ${small} ${options})
  fill_term_of(${WORK}/${name}.json got)
  if(NOT got STREQUAL want)
    message(FATAL_ERROR "calibrate ${options}: validation.fill_term is '${got}', expected '${want}'")
  endif()
  message(STATUS "ok: calibrate ${options}: fill term ${got}")
endforeach()
