# ff_module(NAME DEPS <modules or targets>...)
# Builds src/farfield/NAME/*.cpp into the static library farfield_NAME. Each module is its own library so that a
# module's tests link only what that module may use (DESIGN.md's dependency table) and a broken module does not
# stop the others from building. The target `farfield` links them all. A module with no .cpp yet (headers only)
# becomes an interface library. Each module is also farfield::NAME, the name it has in the installed package
# (cmake/FarfieldInstall.cmake), so a program links the same names in the tree and against an install.
function(ff_module name)
  cmake_parse_arguments(ARG "" "" "DEPS" ${ARGN})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${name}/*.cpp)
  set(includes $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src> $<INSTALL_INTERFACE:include>)
  if(sources)
    add_library(farfield_${name} STATIC ${sources})
    target_include_directories(farfield_${name} PUBLIC ${includes})
    # Warnings are the build's own business: not exported with the module.
    target_link_libraries(farfield_${name} PUBLIC ${ARG_DEPS} PRIVATE $<BUILD_INTERFACE:farfield_warnings>)
    target_compile_features(farfield_${name} PUBLIC cxx_std_20)
    set_target_properties(farfield_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    if(FF_SANITIZE OR FF_FUZZ)
      # Instrumented objects need the sanitizer runtimes wherever they are linked, installed package included.
      target_link_options(farfield_${name} INTERFACE -fsanitize=address,undefined)
    endif()
  else()
    add_library(farfield_${name} INTERFACE)
    target_include_directories(farfield_${name} INTERFACE ${includes})
    target_link_libraries(farfield_${name} INTERFACE ${ARG_DEPS})
    target_compile_features(farfield_${name} INTERFACE cxx_std_20)
  endif()
  set_target_properties(farfield_${name} PROPERTIES EXPORT_NAME ${name})
  add_library(farfield::${name} ALIAS farfield_${name})
  set_property(GLOBAL APPEND PROPERTY FF_MODULES farfield_${name})
endfunction()
