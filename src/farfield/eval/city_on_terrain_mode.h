// A city and a terrain in one frame (issue 18): the city's scene drawn by a walkthrough mode ("culled",
// "dynamic-shade", ...) over a terrain drawn by a terrain technique ("high": the 1 px quadtree LOD, "high-gpu": the
// 1 px CDLOD on the GPU (terrain/gpu_lod.h; its hole left out by the fragment shader), "lod-sprite":
// Chen et al. 1999, choosing per frame between the sprite and the high LOD by this machine's terrain costs, measured
// at prepare() from five views around the city unless the run has them, or "lod-sprite-gpu": the same drawn by the
// CDLOD terrain, sprite frames included), both into the frame's target, the z-buffer deciding between them.
//
// The city must have been made on the same terrain: `farfield gen city --terrain SPEC --terrain-scale S`, then
// `farfield bench city.glb path.json --modes terrain-lod-sprite+culled --mode-option terrain=SPEC --mode-option
// terrain_scale=S`. Its origin lies over the terrain's centre and its heights are the terrain's relative to the
// centre's, times S (terrain_data.h, centred_scale): the terrain is drawn with the camera moved by the centre's
// position, which is the same frame up to a translation. The city's own ground (object "ground": its streets, over
// the terrain's surface) covers the city; the terrain's triangles under it are left out (a hole of whole grid
// cells inside the ground's rectangle), so the two do not fight for the same pixels.
//
// Names: "terrain-T+MODE" for T high, high-gpu, lod-sprite and lod-sprite-gpu, and MODE culled and
// dynamic-shade (registered by
// registerTerrainModes); the mode's own options apply. info(): the city mode's, prefixed "city_", and the terrain's.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "farfield/eval/mode.h"
#include "farfield/eval/terrain_modes.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/terrain_cost.h"

namespace farfield::eval {

class CityOnTerrainMode : public Mode {
 public:
  // terrain: "high" (the quadtree LOD), "high-gpu" (CDLOD, terrain/gpu_lod.h), "lod-sprite" or "lod-sprite-gpu";
  // city: a registered walkthrough mode's name.
  CityOnTerrainMode(std::string terrain, std::string city);
  std::string name() const override { return "terrain-" + terrain_ + "+" + city_; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  // To the city's mode (culled's occlusion_auto times its frames) and to LOD-sprite's cost correction: the whole
  // frame's time, the city's part with it (it adds about the same to every kind of terrain frame, so the choice
  // between them compares the same differences; the keyframe rendered ahead is sliced by the frames' own time).
  void frameMeasured(size_t path_frame, double wall_ms) override;
  std::map<std::string, double> info() const override;

  // The terrain's camera for a city camera (moved by the city origin's position in the terrain's frame), and the
  // grid points left out under the city's ground (tests).
  Camera terrainCamera(const Camera& city_camera) const;
  const terrain::GridRect& hole() const { return hole_; }

 private:
  terrain::TerrainCostOptions calibrationViews(const ModeContext& context) const;

  std::string terrain_, city_;
  std::unique_ptr<Mode> city_mode_;
  std::shared_ptr<TerrainRun> run_;
  std::unique_ptr<terrain::LodSpriteRenderer> sprite_;
  terrain::GridRect hole_;
  Vec3 offset_{0.0f};
  terrain::LodMesh mesh_;
  bool started_ = false;
  size_t last_frame_ = 0;
  uint64_t last_sprite_frame_ = 0;  // LodSpriteFrameInfo::frame of the last frame drawn
  uint64_t terrain_triangles_ = 0;
  size_t frames_ = 0;
};

// Registers "terrain-T+C" for T high, high-gpu and lod-sprite and C culled and dynamic-shade (called by
// registerTerrainModes).
void registerCityOnTerrainModes();

}  // namespace farfield::eval
