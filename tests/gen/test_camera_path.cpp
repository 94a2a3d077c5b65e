// Camera paths: street walks checked by brute force against every block and street, speeds and heights against
// the walker's figures, JSON round trip and malformed files, flyover and orbit geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "farfield/core/error.h"
#include "farfield/core/polygon2d.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gen/street_network.h"
#include "support/test_support.h"

using farfield::Vec2;
using farfield::Vec3;
using farfield::gen::CameraPath;
using farfield::gen::StreetWalkOptions;
using farfield::gen::Walker;
using farfield::urban::StreetGraph;

namespace {

StreetGraph city(int blocks, uint64_t seed) {
  farfield::gen::StreetNetworkOptions o;
  o.blocks = blocks;
  o.seed = seed;
  return farfield::gen::generateStreetNetwork(o);
}

// Distance to the nearest street centreline relative to that street's half-width (brute force over all streets).
double relativeStreetDistance(const StreetGraph& g, const Vec2& p) {
  double best = 1e30;
  for (const auto& s : g.streets())
    best = std::min(best, farfield::distancePointSegment(p, g.position(s.a), g.position(s.b)) / (0.5 * s.width));
  return best;
}

void checkWalk(const StreetGraph& g, const std::vector<farfield::gen::BlockFootprint>& blocks, const CameraPath& path,
               double speed, double eye_height, int frames) {
  ASSERT_EQ(path.frames.size(), size_t(frames));
  EXPECT_EQ(path.kind, "street");
  double total = 0.0;
  int on_speed = 0;
  for (size_t i = 0; i < path.frames.size(); ++i) {
    const auto& f = path.frames[i];
    const Vec2 eye(f.eye.x, f.eye.y);
    // Never inside a block's buildable area.
    for (const auto& b : blocks)
      ASSERT_FALSE(farfield::pointInPolygon(eye, b.footprint)) << "frame " << i << " inside block " << b.face;
    // On a street: closer to some centreline than that street's half-width.
    ASSERT_LT(relativeStreetDistance(g, eye), 1.0) << "frame " << i;
    EXPECT_NEAR(f.eye.z, eye_height, 1e-5);
    EXPECT_NEAR(f.up.z, 1.0f, 1e-6);
    // Looking level, ahead along the direction of travel.
    EXPECT_NEAR(f.at.z, f.eye.z, 1e-4);
    if (i + 1 < path.frames.size()) {
      const Vec3 step = path.frames[i + 1].eye - f.eye;
      const double d = glm::length(step);
      total += d;
      // Each frame moves by the walker's speed; chords across the tightest turns are shorter.
      EXPECT_GT(d * path.fps, 0.5 * speed) << "frame " << i;
      EXPECT_LT(d * path.fps, 1.001 * speed) << "frame " << i;
      if (std::abs(d * path.fps - speed) <= 0.03 * speed) ++on_speed;
      EXPECT_GT(glm::dot(f.at - f.eye, step), 0.0f) << "frame " << i;
    }
  }
  EXPECT_NEAR(total * path.fps / (frames - 1), speed, 0.02 * speed);
  EXPECT_GE(on_speed, 0.99 * (frames - 1));
}

}  // namespace

TEST(CameraPath, PedestrianWalkStaysOnTheStreets) {
  const StreetGraph g = city(80, 3);
  const auto blocks = farfield::gen::buildableBlocks(g);
  for (uint64_t seed : {1u, 2u, 3u, 4u}) {
    StreetWalkOptions o;
    o.seed = seed;
    o.frames = 2400;  // 112 m: several junctions
    const CameraPath path = farfield::gen::streetWalk(g, o);
    checkWalk(g, blocks, path, 1.4, 1.7, o.frames);
    EXPECT_FLOAT_EQ(path.fps, 30.0f);
  }
}

TEST(CameraPath, CarWalkStaysOnTheStreets) {
  const StreetGraph g = city(120, 8);
  const auto blocks = farfield::gen::buildableBlocks(g);
  for (uint64_t seed : {5u, 6u, 7u}) {
    StreetWalkOptions o;
    o.seed = seed;
    o.frames = 900;  // 300 m
    o.walker = Walker::Car;
    checkWalk(g, blocks, farfield::gen::streetWalk(g, o), 10.0, 1.2, o.frames);
  }
}

TEST(CameraPath, WalkFollowsTheGroundAndTheSeed) {
  const StreetGraph g = city(40, 2);
  StreetWalkOptions o;
  o.frames = 300;
  o.seed = 11;
  o.ground_height = [](float x, float y) { return 0.01f * x + 0.02f * y + 5.0f; };
  const CameraPath a = farfield::gen::streetWalk(g, o);
  for (const auto& f : a.frames) {
    EXPECT_NEAR(f.eye.z, 0.01f * f.eye.x + 0.02f * f.eye.y + 5.0f + 1.7f, 1e-3);
    EXPECT_NEAR(f.at.z, 0.01f * f.at.x + 0.02f * f.at.y + 5.0f + 1.7f, 1e-3);
  }
  const CameraPath b = farfield::gen::streetWalk(g, o);
  o.seed = 12;
  const CameraPath c = farfield::gen::streetWalk(g, o);
  bool differs = false;
  for (size_t i = 0; i < a.frames.size(); ++i) {
    EXPECT_EQ(a.frames[i].eye, b.frames[i].eye);
    differs = differs || a.frames[i].eye != c.frames[i].eye;
  }
  EXPECT_TRUE(differs);
}

TEST(CameraPath, DeadEndTurnsBack) {
  // A single 40 m street: the walker must turn at both ends and stay on it.
  const StreetGraph g = StreetGraph::build({{0, 0}, {40, 0}}, {{0, 1, 10.0f, 1}}, "one street");
  StreetWalkOptions o;
  o.frames = 3000;  // 140 m: at least two U-turns
  const CameraPath path = farfield::gen::streetWalk(g, o);
  float min_x = 1e9f, max_x = -1e9f;
  for (const auto& f : path.frames) {
    const Vec2 eye(f.eye.x, f.eye.y);
    EXPECT_LT(farfield::distancePointSegment(eye, Vec2(0, 0), Vec2(40, 0)), 5.0);
    min_x = std::min(min_x, f.eye.x);
    max_x = std::max(max_x, f.eye.x);
  }
  EXPECT_LT(min_x, 5.0f);
  EXPECT_GT(max_x, 35.0f);
}

TEST(CameraPath, EyeBoundsAreTheDistrictAroundThePath) {
  CameraPath path;
  for (const Vec3& eye : {Vec3(10.0f, 20.0f, 1.2f), Vec3(30.0f, -5.0f, 1.2f), Vec3(15.0f, 0.0f, 1.3f)}) {
    farfield::gen::PathFrame f;
    f.eye = eye;
    f.at = eye + Vec3(1.0f, 0.0f, 0.0f);
    path.frames.push_back(f);
  }
  const farfield::Box3 box = farfield::gen::eyeBounds(path, 50.0f, "p.json");
  EXPECT_FLOAT_EQ(box.lo.x, -40.0f);
  EXPECT_FLOAT_EQ(box.hi.x, 80.0f);
  EXPECT_FLOAT_EQ(box.lo.y, -55.0f);
  EXPECT_FLOAT_EQ(box.hi.y, 70.0f);
  EXPECT_FLOAT_EQ(box.lo.z, 1.2f);
  EXPECT_FLOAT_EQ(box.hi.z, 1.7f);  // at least 0.5 m tall
  for (const farfield::gen::PathFrame& f : path.frames) EXPECT_TRUE(box.contains(f.eye));
  EXPECT_THROW(farfield::gen::eyeBounds(path, -1.0f, "p.json"), farfield::Error);
  EXPECT_THROW(farfield::gen::eyeBounds(CameraPath{}, 1.0f, "p.json"), farfield::Error);
}

TEST(CameraPath, JsonRoundTrip) {
  const StreetGraph g = city(30, 4);
  StreetWalkOptions o;
  o.frames = 50;
  o.fov_deg = 72.0f;
  const CameraPath path = farfield::gen::streetWalk(g, o);
  const auto dir = farfield::test::scratchDir("camera_path_json");
  const std::string file = (dir / "walk.json").string();
  farfield::gen::saveCameraPath(path, file);
  const CameraPath back = farfield::gen::loadCameraPath(file);
  EXPECT_EQ(back.kind, "street");
  EXPECT_FLOAT_EQ(back.fps, 30.0f);
  ASSERT_EQ(back.frames.size(), path.frames.size());
  for (size_t i = 0; i < path.frames.size(); ++i) {
    EXPECT_EQ(back.frames[i].eye, path.frames[i].eye);
    EXPECT_EQ(back.frames[i].at, path.frames[i].at);
    EXPECT_EQ(back.frames[i].up, path.frames[i].up);
    EXPECT_NEAR(back.frames[i].fov_y, 72.0 * farfield::kPi / 180.0, 1e-6);
  }
  const farfield::Camera cam = back.camera(3, 640, 360);
  EXPECT_EQ(cam.eye, path.frames[3].eye);
  EXPECT_EQ(cam.at, path.frames[3].at);
  EXPECT_EQ(cam.width, 640);
  EXPECT_EQ(cam.height, 360);
  EXPECT_THROW(back.camera(50, 640, 360), farfield::Error);
}

TEST(CameraPath, BadFilesNameTheFileAndFrame) {
  struct Case {
    std::string name, text, expect;
  };
  const std::string good = R"({"eye": [0,0,2], "at": [0,1,2], "up": [0,0,1], "fov_deg": 60})";
  const std::vector<Case> cases{
      {"notjson.json", "{ nope", "not valid JSON"},
      {"noframes.json", R"({"kind": "street", "fps": 30})", "frames"},
      {"empty.json", R"({"frames": []})", "no frames"},
      {"fps.json", R"({"fps": -1, "frames": [)" + good + "]}", "fps"},
      {"noeye.json", R"({"frames": [)" + good + R"(, {"at": [0,1,2]}]})", "frame 1: missing \"eye\""},
      {"nan.json", R"({"frames": [)" + good + "," + good + R"(, {"eye": [0,null,2], "at": [0,1,2]}]})",
       "frame 2"},
      {"huge.json", R"({"frames": [{"eye": [0,1e39,2], "at": [0,1,2]}]})", "frame 0"},
      {"same.json", R"({"frames": [{"eye": [1,1,1], "at": [1,1,1]}]})", "frame 0: \"eye\" and \"at\" coincide"},
      {"up.json", R"({"frames": [{"eye": [0,0,0], "at": [0,0,5], "up": [0,0,1]}]})", "frame 0: \"up\""},
      {"fov.json", R"({"frames": [{"eye": [0,0,0], "at": [0,1,0], "fov_deg": 200}]})", "frame 0: \"fov_deg\""},
  };
  for (const Case& c : cases) {
    const auto dir = farfield::test::scratchDir("camera_path_bad");
    const std::string file = (dir / c.name).string();
    std::ofstream(file) << c.text;
    try {
      farfield::gen::loadCameraPath(file);
      ADD_FAILURE() << c.name << ": no error";
    } catch (const farfield::Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(file), std::string::npos) << what;
      EXPECT_NE(what.find(c.expect), std::string::npos) << c.name << ": " << what;
    }
  }
  EXPECT_THROW(farfield::gen::loadCameraPath("/nonexistent/path.json"), farfield::Error);
}

TEST(CameraPath, FlyoverAndOrbitGeometry) {
  farfield::Box3 box;
  box.expand(Vec3(-100, -50, 0));
  box.expand(Vec3(300, 250, 40));
  farfield::gen::FlyoverOptions fo;
  fo.frames = 11;
  fo.altitude = 120.0f;
  const CameraPath fly = farfield::gen::flyover(box, fo);
  ASSERT_EQ(fly.frames.size(), 11u);
  EXPECT_EQ(fly.kind, "flyover");
  EXPECT_NEAR(fly.frames.front().eye.x, -100.0f, 1e-3);
  EXPECT_NEAR(fly.frames.front().eye.y, -50.0f, 1e-3);
  EXPECT_NEAR(fly.frames.back().eye.x, 300.0f, 1e-3);
  EXPECT_NEAR(fly.frames.back().eye.y, 250.0f, 1e-3);
  for (size_t i = 0; i < fly.frames.size(); ++i) {
    const auto& f = fly.frames[i];
    EXPECT_NEAR(f.eye.z, 120.0f, 1e-3);
    EXPECT_LT(f.at.z, f.eye.z);  // looking down
    // Looking ahead: the horizontal view direction is the direction of flight (400, 300)/500.
    const Vec2 h = glm::normalize(Vec2(f.at - f.eye));
    EXPECT_NEAR(h.x, 0.8f, 1e-4);
    EXPECT_NEAR(h.y, 0.6f, 1e-4);
    if (i > 0) {
      EXPECT_NEAR(glm::length(f.eye - fly.frames[i - 1].eye), 50.0f, 1e-3);  // 500 m in 10 steps
    }
  }

  farfield::gen::OrbitOptions oo;
  oo.frames = 36;
  oo.radius_scale = 1.5f;
  oo.elevation_deg = 30.0f;
  const CameraPath orb = farfield::gen::orbit(box, oo);
  ASSERT_EQ(orb.frames.size(), 36u);
  const Vec3 centre(100, 100, 20);
  const float radius = 1.5f * 0.5f * std::sqrt(400.0f * 400 + 300.0f * 300 + 40.0f * 40);
  for (const auto& f : orb.frames) {
    EXPECT_NEAR(glm::length(f.eye - centre), radius, 1e-2);
    EXPECT_NEAR(f.eye.z - centre.z, radius * 0.5f, 1e-2);  // sin 30 degrees
    EXPECT_NEAR(glm::length(f.at - centre), 0.0f, 1e-4);
  }
  // A full circle: consecutive frames 10 degrees apart, the first and the last too.
  const float chord = 2.0f * radius * std::cos(float(farfield::kPi) / 6.0f) * std::sin(float(farfield::kPi) / 36.0f);
  EXPECT_NEAR(glm::length(orb.frames[1].eye - orb.frames[0].eye), chord, 1e-2);
  EXPECT_NEAR(glm::length(orb.frames[0].eye - orb.frames[35].eye), chord, 1e-2);

  EXPECT_THROW(farfield::gen::orbit(farfield::Box3(), oo), farfield::Error);
  fo.frames = 0;
  EXPECT_THROW(farfield::gen::flyover(box, fo), farfield::Error);
  StreetWalkOptions so;
  EXPECT_THROW(farfield::gen::streetWalk(StreetGraph(), so), farfield::Error);
}
