// Camera paths of the terrain experiment (eval/terrain_paths.h), no GL: resampling against hand-computed frames,
// clip planes against the terrain's corners, the flythrough as a camera path.
#include "farfield/eval/terrain_paths.h"

#include <gtest/gtest.h>

#include <cmath>

#include "farfield/core/camera.h"
#include "farfield/core/error.h"
#include "farfield/terrain/fractal.h"

namespace farfield::eval {
namespace {

gen::CameraPath threeFrames() {
  gen::CameraPath p;
  p.kind = "test";
  for (int i = 0; i < 3; ++i) {
    gen::PathFrame f;
    f.eye = Vec3(10.0f * float(i), 0.0f, 100.0f + 20.0f * float(i * i));
    f.at = f.eye + Vec3(0.0f, 50.0f, -50.0f);
    f.fov_y = 0.5f + 0.25f * float(i);
    p.frames.push_back(f);
  }
  return p;
}

TEST(TerrainPaths, ResampleKeepsTheEndsAndInterpolatesBetweenFrames) {
  const gen::CameraPath p = threeFrames();
  const gen::CameraPath r = resampleCameraPath(p, 5);
  ASSERT_EQ(r.frames.size(), 5u);
  EXPECT_EQ(r.kind, "test");
  // Frames 0, 2, 4 of five are frames 0, 1, 2 of three; 1 and 3 lie halfway between.
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(glm::length(r.frames[2 * i].eye - p.frames[i].eye), 0.0f, 1e-4f) << i;
    EXPECT_NEAR(r.frames[2 * i].fov_y, p.frames[i].fov_y, 1e-6f) << i;
  }
  EXPECT_NEAR(glm::length(r.frames[1].eye - Vec3(5.0f, 0.0f, 110.0f)), 0.0f, 1e-4f);
  EXPECT_NEAR(glm::length(r.frames[3].eye - Vec3(15.0f, 0.0f, 150.0f)), 0.0f, 1e-4f);
  EXPECT_NEAR(r.frames[3].fov_y, 0.875f, 1e-6f);
  EXPECT_EQ(resampleCameraPath(p, 1).frames.size(), 1u);
  const gen::CameraPath same = resampleCameraPath(p, 3);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(glm::length(same.frames[i].at - p.frames[i].at), 0.0f, 1e-4f);
}

TEST(TerrainPaths, ClipPlanesHoldEveryCornerOfTheTerrain) {
  terrain::Heightfield hf(33, 17, 30.0);
  for (int j = 0; j < hf.height; ++j)
    for (int i = 0; i < hf.width; ++i) hf.at(i, j) = float(i + 3 * j);
  const gen::CameraPath p = threeFrames();
  const ClipPlanes planes = terrainClipPlanes(hf, p);
  EXPECT_EQ(planes.near_plane, 2.0f);
  const Box3 b = hf.bounds();
  for (const gen::PathFrame& f : p.frames)
    for (int k = 0; k < 8; ++k) {
      const Vec3 c((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z);
      EXPECT_GT(planes.far_plane, glm::length(c - f.eye));
    }
  // A small terrain seen from nearby still gets the 1 km minimum.
  terrain::Heightfield tiny(3, 3, 1.0);
  EXPECT_EQ(terrainClipPlanes(tiny, p).far_plane, 1000.0f);
}

TEST(TerrainPaths, FlythroughIsACameraPathOverTheTerrain) {
  terrain::FractalOptions f;
  f.size = 65;
  const terrain::Heightfield hf = terrain::fractalTerrain(f);
  terrain::FlythroughOptions o;
  o.frames = 12;
  o.fov_deg = 50.0f;
  const gen::CameraPath p = flythroughCameraPath(hf, o);
  EXPECT_EQ(p.kind, "terrain-flythrough");
  ASSERT_EQ(p.frames.size(), 12u);
  for (const gen::PathFrame& frame : p.frames) {
    EXPECT_EQ(frame.up, Vec3(0.0f, 0.0f, 1.0f));
    EXPECT_NEAR(frame.fov_y, float(degToRad(50.0)), 1e-5f);
  }
  o.frames = 1;
  EXPECT_THROW(flythroughCameraPath(hf, o), Error);
}

}  // namespace
}  // namespace farfield::eval
