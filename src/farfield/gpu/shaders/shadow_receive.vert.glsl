#version 450 core
// Farfield shadow receivers (gpu/shadow_map.h): the tiles to shade as triangles whose corners are pixel positions.
layout(location = 0) in ivec2 a_pixel;
uniform vec2 u_size;  // the target's width and height
void main() { gl_Position = vec4(vec2(a_pixel) / u_size * 2.0 - 1.0, 0.0, 1.0); }
