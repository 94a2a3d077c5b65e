// A terrain ready to render: the heightfield (cropped to whole LOD blocks), its quadtree LOD, the original texture,
// and the full-resolution mesh as a scene (the benchmark's full-geometry baseline and reference).
#pragma once

#include <memory>
#include <string>

#include "farfield/image/image.h"
#include "farfield/scene/scene.h"
#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/heightfield.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/terrain_texture.h"

namespace farfield::terrain {

struct TerrainLoadOptions {
  int block = 128;        // LOD block size (cells); the heightfield is cropped (centred) to whole blocks
  int texture_scale = 1;  // texels per cell
  std::string texture;    // a PNG to use as the original texture instead of the generated one ("" = generate)
  DemLoadOptions dem;     // how a DEM file is read (band, cell size, height scale, size limit)
  // > 0: heights relative to the terrain's height at its centre, times this scale: the ground a city made with
  // `farfield gen city --terrain SPEC --terrain-scale S` stands on (its z = 0 at the centre). 0 = heights as loaded.
  float centred_scale = 0.0f;
};

// "fractal:SIZE[:SEED][:relief=M][:roughness=R][:cell=M]" -> the fractal's options (the others at their defaults;
// relief and cell in metres, see fractal.h). Throws farfield::Error naming the spec for anything else: a sign, a
// space, trailing text, a SIZE beyond int, a SEED beyond 64 bits, an unknown key or a value that is not a positive
// number (fractalTerrain then checks that SIZE is 2^n + 1 and the ranges).
FractalOptions parseFractalSpec(const std::string& spec);

// Whether spec names a fractal ("fractal:...") rather than a DEM file.
inline bool isFractalSpec(const std::string& spec) { return spec.rfind("fractal:", 0) == 0; }
// The heightfield a spec names: the fractal it describes (parseFractalSpec) or the DEM file loaded whole (loadDem,
// with `dem`). Throws farfield::Error for bad specs or files.
Heightfield loadHeightfield(const std::string& spec, const DemLoadOptions& dem = {});

struct TerrainData {
  Heightfield source;  // as loaded (before cropping)
  Heightfield hf;      // cropped to whole LOD blocks; the terrain everything renders
  int crop_i0 = 0, crop_j0 = 0;  // position of hf's grid point (0, 0) in `source`
  DVec2 source_centre{0.0};     // the centre of `source` in hf's local frame (metres): where a city's origin lies
  std::unique_ptr<QuadtreeLod> lod;
  image::ColorImage texture;

  // spec: a DEM file (see dem_io.h) or "fractal:SIZE[:SEED]" (see fractal.h; SIZE = 2^n + 1, SEED a whole number
  // 0..2^64-1, both in decimal digits only). Throws farfield::Error for bad files or specs.
  static std::unique_ptr<TerrainData> load(const std::string& spec, const TerrainLoadOptions& options = {});
  // One-line description: size, cell size, height range, nodata count, crop.
  std::string describe() const;
  // The full-resolution grid (two triangles per cell) as a one-object scene with the original texture, unlit.
  scene::Scene fullResolutionScene() const;
};

}  // namespace farfield::terrain
