#version 450 core
// Farfield shadow receivers (gpu/shadow_map.h): one triangle covering the screen, no vertex buffer.
void main() {
  const vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
