#include "city_terrain.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include "farfield/core/error.h"
#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/terrain_data.h"

namespace farfield::app {

std::string setCityTerrain(gen::CityOptions& options, const std::string& spec, float vertical_scale) {
  if (!(vertical_scale > 0.0f && std::isfinite(vertical_scale)))
    throw Error("--terrain-scale", "must be a finite number > 0");
  auto hf = std::make_shared<const terrain::Heightfield>(terrain::loadHeightfield(spec));
  if (hf->width < 2 || hf->height < 2) throw Error(spec, "the terrain needs at least 2 x 2 grid points");
  const double cx = 0.5 * hf->extentX(), cy = 0.5 * hf->extentY();
  const float base = hf->sample(cx, cy);
  options.ground = [hf, cx, cy, base, vertical_scale](Vec2 p) {
    return vertical_scale * (hf->sample(cx + double(p.x), cy + double(p.y)) - base);
  };
  // Half the terrain's cell: the ground's triangles, whose vertices do not fall on the terrain's grid points, stay
  // closer to its bilinear surface, on which the buildings stand.
  options.ground_cell = float(std::max(0.5, 0.5 * std::min(hf->cell_x, hf->cell_y)));
  char line[512];
  std::snprintf(line, sizeof line,
                "%s, %d x %d points of %.1f m, %.0f-%.0f m (x %.2f, relative to %.0f m at its centre)",
                hf->source.c_str(), hf->width, hf->height, std::min(hf->cell_x, hf->cell_y), double(hf->minHeight()),
                double(hf->maxHeight()), double(vertical_scale), double(base));
  return line;
}

}  // namespace farfield::app
