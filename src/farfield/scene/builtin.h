// Built-in scenes for demos and tests, addressed on the command line as "builtin:NAME".
#pragma once

#include <string>
#include <vector>

#include "farfield/scene/mesh.h"
#include "farfield/scene/scene.h"

namespace farfield::scene {

// Axis-aligned box mesh [lo, hi] with outward normals and per-face uvs (0..1), 12 triangles.
Mesh makeBox(const Vec3& lo, const Vec3& hi);
// Unit cube [-0.5, 0.5]^3.
Mesh makeUnitCube();
// Ground quad on z = 0 covering [lo, hi] in x, y; uvs repeat every uv_scale metres.
Mesh makeGroundQuad(const Vec2& lo, const Vec2& hi, float uv_scale = 10.0f);
// UV sphere.
Mesh makeSphere(float radius, int segments = 32, int rings = 16);

// "cube": one unit cube at the origin, red. "cubes": a ground plane and a 5x5 grid of coloured boxes of varied
// heights with a checker texture, a small test scene that exercises textures, depth and ids.
std::vector<std::string> builtinSceneNames();
// Throws farfield::Error for an unknown name.
Scene builtinScene(const std::string& name);

}  // namespace farfield::scene
