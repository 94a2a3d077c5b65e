# The installed package, as an engine's build sees it: `cmake --install` of this build into a scratch prefix, the
# prefix moved elsewhere (relocatable: no path of the build, the sources or the first prefix in its CMake files),
# then examples/ configured and built on its own against it with find_package(farfield), a program linking
# farfield::farfield (every exported module and dependency resolves), and the installed `farfield` tool and the
# freshly built example run on a small city. Run by ctest with -DBUILD_DIR=<this build> -DSOURCE_DIR=<sources>
# -DWORK=<scratch dir> -DCXX=<compiler> -DBUILD_TYPE=<build type>.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
include(${CMAKE_CURRENT_LIST_DIR}/cli_helpers.cmake)

# Install, then look for paths that would tie the package to this machine's build.
set(stage ${WORK}/stage)
run_ok(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${stage})
foreach(required lib/cmake/farfield/farfieldConfig.cmake lib/cmake/farfield/farfieldConfigVersion.cmake
                 lib/libfarfield_runtime.a include/farfield/runtime/walkthrough.h include/farfield/gpu/renderer.h
                 bin/farfield)
  if(NOT EXISTS ${stage}/${required})
    message(FATAL_ERROR "the installed package has no ${required}")
  endif()
endforeach()
file(GLOB_RECURSE package_texts ${stage}/lib/cmake/* ${stage}/include/*)
foreach(file IN LISTS package_texts)
  file(READ ${file} text)
  foreach(path ${BUILD_DIR} ${SOURCE_DIR} ${stage})
    string(FIND "${text}" "${path}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "${file} holds the path ${path}: the package is not relocatable")
    endif()
  endforeach()
endforeach()

# Move it: everything below must work from the new place only.
set(prefix ${WORK}/moved/farfield)
file(MAKE_DIRECTORY ${WORK}/moved)
file(RENAME ${stage} ${prefix})
set(configure_args -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=${BUILD_TYPE})

# examples/ on its own, the way docs/EMBEDDING.md tells an engineer to build it.
run_ok(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples -B ${WORK}/examples ${configure_args})
run_ok(${CMAKE_COMMAND} --build ${WORK}/examples -j2)
foreach(example embed_walkthrough embed_terrain)
  if(NOT EXISTS ${WORK}/examples/${example})
    message(FATAL_ERROR "examples/ built on its own against the package made no ${example}")
  endif()
endforeach()

# Every exported target exists and farfield::farfield links (each module's dependencies found again).
file(GLOB module_libs RELATIVE ${prefix}/lib ${prefix}/lib/libfarfield_*.a)
string(REGEX REPLACE "libfarfield_([a-z]+)\\.a" "\\1" modules "${module_libs}")
file(WRITE ${WORK}/all/CMakeLists.txt "cmake_minimum_required(VERSION 3.25)
project(farfield_all LANGUAGES CXX)
find_package(farfield CONFIG REQUIRED)
foreach(m ${modules} farfield)
  if(NOT TARGET farfield::\${m})
    message(FATAL_ERROR \"find_package(farfield) gave no target farfield::\${m}\")
  endif()
endforeach()
add_executable(link_all main.cpp)
target_link_libraries(link_all PRIVATE farfield::farfield)
")
file(WRITE ${WORK}/all/main.cpp "#include \"farfield/core/error.h\"\n#include \"farfield/runtime/walkthrough.h\"\n"
     "int main() { return farfield::runtime::WalkthroughOptions{}.error_px >= 0.0 ? 0 : 1; }\n")
run_ok(${CMAKE_COMMAND} -S ${WORK}/all -B ${WORK}/all/build ${configure_args})
run_ok(${CMAKE_COMMAND} --build ${WORK}/all/build)
run_ok(${WORK}/all/build/link_all)

# The installed tool makes a small city and its database; the example built against the package walks it.
set(FARFIELD ${prefix}/bin/farfield)
run_ok(${FARFIELD} gen city --blocks 12 --detail 0 --seed 4 -o ${WORK}/city.glb)
run_ok(${FARFIELD} path street ${WORK}/city.streets.json --frames 20 --fps 5 --seed 4 --car -o ${WORK}/drive.json)
run_ok(${FARFIELD} bake ${WORK}/city.glb --pipeline pvs,near-far,mmi --resolution 128 --pvs-face 32 --pvs-spacing 10
       --path ${WORK}/drive.json -o ${WORK}/imp)
run_ok(${WORK}/examples/embed_walkthrough ${WORK}/city.glb ${WORK}/imp ${WORK}/drive.json 4 ${WORK}/last.png)
if(NOT LAST_OUT MATCHES "error bound: 4.00 px" OR NOT LAST_OUT MATCHES "layers drawn as impostors [0-9]+ times")
  message(FATAL_ERROR "the installed-package embed_walkthrough did not report its plan:\n${LAST_OUT}")
endif()
if(NOT EXISTS ${WORK}/last.png)
  message(FATAL_ERROR "the installed-package embed_walkthrough did not write its frame")
endif()
