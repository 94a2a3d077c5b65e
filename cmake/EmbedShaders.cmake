# ff_embed_shaders(TARGET target DIR dir): every dir/*.glsl becomes a string in a generated source file,
# reachable through farfield::gpu::shaderSource("name.glsl"). The generated file is rebuilt when a shader changes.
function(ff_embed_shaders)
  cmake_parse_arguments(ARG "" "TARGET;DIR" "" ${ARGN})
  file(GLOB shaders CONFIGURE_DEPENDS ${ARG_DIR}/*.glsl)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/embedded_shaders.cpp)
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} -DSHADERS="${shaders}" -P ${PROJECT_SOURCE_DIR}/cmake/embed_shaders_script.cmake
    DEPENDS ${shaders} ${PROJECT_SOURCE_DIR}/cmake/embed_shaders_script.cmake
    COMMENT "Embedding GLSL shaders")
  target_sources(${ARG_TARGET} PRIVATE ${out})
endfunction()
