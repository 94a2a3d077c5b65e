// Camera paths over builtin:cubes for the eval tests (built in code, no files). The scene: a 24 m ground quad
// centred on the origin and a 5x5 grid of 2 m boxes at x, y in {-8, -4, 0, 4, 8}.
#pragma once

#include "farfield/gen/camera_path.h"

namespace farfield::test {

// Walks along y = -14 at eye height 2.5 m from x = -8 to x = 8, looking north (+y) and slightly down with a 40
// degree field of view: every frame sees some boxes and leaves others out of the frustum (those far to the side).
inline gen::CameraPath sideWalkPath(int frames = 4) {
  gen::CameraPath path;
  path.kind = "test";
  for (int i = 0; i < frames; ++i) {
    const float x = frames > 1 ? -8.0f + 16.0f * float(i) / float(frames - 1) : 0.0f;
    gen::PathFrame f;
    f.eye = Vec3(x, -14.0f, 2.5f);
    f.at = Vec3(x, -6.0f, 1.0f);
    f.up = Vec3(0.0f, 0.0f, 1.0f);
    f.fov_y = float(degToRad(40.0));
    path.frames.push_back(f);
  }
  return path;
}

// One frame looking straight up from 3 m: nothing of the scene is in view.
inline gen::PathFrame skyFrame() {
  gen::PathFrame f;
  f.eye = Vec3(0.0f, -14.0f, 3.0f);
  f.at = Vec3(0.0f, -14.0f, 10.0f);
  f.up = Vec3(0.0f, 1.0f, 0.0f);
  f.fov_y = float(degToRad(40.0));
  return f;
}

}  // namespace farfield::test
