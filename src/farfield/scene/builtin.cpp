// Built-in meshes and scenes. Front faces are counter-clockwise seen from outside (OpenGL's default), Z is up,
// and uvs follow glTF: (0, 0) is the top-left of the texture image (row 0), v grows down the rows.
#include "farfield/scene/builtin.h"

#include <cmath>
#include <memory>

#include "farfield/core/error.h"

namespace farfield::scene {

namespace {

// Appends one quad with corners c0..c3 (counter-clockwise seen from the side the normal points to).
void addQuad(Mesh& mesh, const Vec3 (&c)[4], const Vec3& normal, const Vec2 (&uv)[4]) {
  const uint32_t base = uint32_t(mesh.positions.size());
  for (int k = 0; k < 4; ++k) {
    mesh.positions.push_back(c[k]);
    mesh.normals.push_back(normal);
    mesh.uvs.push_back(uv[k]);
  }
  for (uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + k);
}

// Two-colour checker of square x square pixel cells; tiles seamlessly under repeat wrapping when size is a
// multiple of 2 * square.
std::shared_ptr<const image::ColorImage> checkerTexture(int size, int square, image::Rgba8 a, image::Rgba8 b) {
  auto img = std::make_shared<image::ColorImage>(size, size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) img->at(x, y) = ((x / square + y / square) % 2 == 0) ? a : b;
  return img;
}

// Fully saturated colour for a hue in [0, 1), value v.
Vec3 hueColor(float hue, float v) {
  const float h = hue * 6.0f;
  const int sector = int(h) % 6;
  const float f = h - std::floor(h);
  switch (sector) {
    case 0: return {v, v * f, 0.0f};
    case 1: return {v * (1.0f - f), v, 0.0f};
    case 2: return {0.0f, v, v * f};
    case 3: return {0.0f, v * (1.0f - f), v};
    case 4: return {v * f, 0.0f, v};
    default: return {v, 0.0f, v * (1.0f - f)};
  }
}

Scene cubeScene() {
  Scene scene;
  Material red;
  red.name = "red";
  red.base_color = {1.0f, 0.0f, 0.0f, 1.0f};
  const uint32_t mat = scene.addMaterial(red);
  const uint32_t mesh = scene.addMesh(makeUnitCube());
  Object cube;
  cube.name = "cube";
  cube.parts.push_back({mesh, mat});
  cube.footprint = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, 0.5f}, {-0.5f, 0.5f}};
  scene.addObject(cube);
  return scene;
}

Scene cubesScene() {
  Scene scene;
  constexpr int kGrid = 5;
  constexpr float kSpacing = 4.0f;  // metres between box centres
  constexpr float kHalf = 1.0f;     // boxes are 2 m x 2 m
  constexpr float kGroundHalf = 12.0f;

  Material ground_mat;
  ground_mat.name = "ground";
  ground_mat.base_color = {1.0f, 1.0f, 1.0f, 1.0f};
  ground_mat.texture = checkerTexture(64, 8, {200, 200, 200, 255}, {90, 90, 90, 255});
  const uint32_t ground_material = scene.addMaterial(ground_mat);
  Object ground;
  ground.name = "ground";
  ground.parts.push_back(
      {scene.addMesh(makeGroundQuad({-kGroundHalf, -kGroundHalf}, {kGroundHalf, kGroundHalf})), ground_material});
  scene.addObject(ground);

  for (int j = 0; j < kGrid; ++j)
    for (int i = 0; i < kGrid; ++i) {
      const int k = j * kGrid + i;
      const float cx = (float(i) - 2.0f) * kSpacing, cy = (float(j) - 2.0f) * kSpacing;
      const float height = 1.0f + 0.5f * float((i * 3 + j * 7) % 9);  // 1 .. 5 m
      Material m;
      m.name = "box_" + std::to_string(i) + "_" + std::to_string(j);
      // Hues spaced by the golden ratio keep neighbouring boxes clearly distinct.
      m.base_color = Vec4(hueColor(std::fmod(float(k) * 0.618034f, 1.0f), 0.9f), 1.0f);
      Object box;
      box.name = m.name;
      box.parts.push_back({scene.addMesh(makeBox({cx - kHalf, cy - kHalf, 0.0f}, {cx + kHalf, cy + kHalf, height})),
                           scene.addMaterial(m)});
      box.footprint = {{cx - kHalf, cy - kHalf}, {cx + kHalf, cy - kHalf}, {cx + kHalf, cy + kHalf},
                       {cx - kHalf, cy + kHalf}};
      scene.addObject(box);
    }
  return scene;
}

}  // namespace

Mesh makeBox(const Vec3& lo, const Vec3& hi) {
  // Each face is given by its outward normal n and two in-face axes u, v with cross(u, v) == n, so corners
  // walked (0,0) (1,0) (1,1) (0,1) in (u, v) are counter-clockwise seen from outside.
  struct Face {
    Vec3 n, u, v;
  };
  static const Face kFaces[6] = {
      {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},   {{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}},
      {{0, 1, 0}, {-1, 0, 0}, {0, 0, 1}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
      {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},   {{0, 0, -1}, {1, 0, 0}, {0, -1, 0}},
  };
  const Vec3 center = (lo + hi) * 0.5f, ext = hi - lo;
  Mesh mesh;
  for (const Face& f : kFaces) {
    Vec3 c[4];
    const float st[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    Vec2 uv[4];
    for (int k = 0; k < 4; ++k) {
      c[k] = center + 0.5f * f.n * ext + (st[k][0] - 0.5f) * f.u * ext + (st[k][1] - 0.5f) * f.v * ext;
      uv[k] = {st[k][0], 1.0f - st[k][1]};  // the face's "up" (v axis) is the image's top row
    }
    addQuad(mesh, c, f.n, uv);
  }
  mesh.computeBounds();
  return mesh;
}

Mesh makeUnitCube() { return makeBox(Vec3(-0.5f), Vec3(0.5f)); }

Mesh makeGroundQuad(const Vec2& lo, const Vec2& hi, float uv_scale) {
  Mesh mesh;
  const Vec3 c[4] = {{lo.x, lo.y, 0.0f}, {hi.x, lo.y, 0.0f}, {hi.x, hi.y, 0.0f}, {lo.x, hi.y, 0.0f}};
  const float s = uv_scale > 0.0f ? uv_scale : 1.0f;
  // North (+y) is towards the image's top row.
  Vec2 uv[4];
  for (int k = 0; k < 4; ++k) uv[k] = {(c[k].x - lo.x) / s, (hi.y - c[k].y) / s};
  addQuad(mesh, c, {0.0f, 0.0f, 1.0f}, uv);
  mesh.computeBounds();
  return mesh;
}

Mesh makeSphere(float radius, int segments, int rings) {
  if (segments < 3) segments = 3;
  if (rings < 2) rings = 2;
  Mesh mesh;
  // Ring 0 is the north pole (+z); the seam column j == segments duplicates j == 0 with u == 1.
  for (int i = 0; i <= rings; ++i) {
    const double theta = kPi * double(i) / double(rings);
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2.0 * kPi * double(j) / double(segments);
      const Vec3 n(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
                   float(std::cos(theta)));
      mesh.positions.push_back(n * radius);
      mesh.normals.push_back(n);
      mesh.uvs.push_back({float(j) / float(segments), float(i) / float(rings)});
    }
  }
  const uint32_t row = uint32_t(segments + 1);
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = uint32_t(i) * row + uint32_t(j), b = a + row, c = b + 1, d = a + 1;
      // Going down a ring and along increasing phi is counter-clockwise seen from outside. The pole rows have
      // one degenerate triangle per quad, which is left out.
      if (i != rings - 1) mesh.indices.insert(mesh.indices.end(), {a, b, c});
      if (i != 0) mesh.indices.insert(mesh.indices.end(), {a, c, d});
    }
  mesh.computeBounds();
  return mesh;
}

std::vector<std::string> builtinSceneNames() { return {"cube", "cubes"}; }

Scene builtinScene(const std::string& name) {
  if (name == "cube") return cubeScene();
  if (name == "cubes") return cubesScene();
  std::string known;
  for (const std::string& n : builtinSceneNames()) known += (known.empty() ? "" : ", ") + n;
  throw Error("builtin:" + name, "unknown built-in scene (known: " + known + ")");
}

}  // namespace farfield::scene
