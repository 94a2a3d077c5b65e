// Placement options: their checks, and their JSON as saved in the database (whole) and read back (strictly).
#include "farfield/bake/place.h"

#include <cmath>
#include <string>
#include <vector>

#include "farfield/bake/place_steps.h"
#include "farfield/core/error.h"
#include "farfield/core/strict_json.h"

namespace farfield::bake {

void validate(const PlaceOptions& o) {
  if (!(o.t_max_ms > 0.0) || !std::isfinite(o.t_max_ms)) throw Error("--tmax", "must be a positive number of ms");
  if (!(o.error_px > 0.0) || !std::isfinite(o.error_px)) throw Error("--error-px", "must be a positive number");
  if (o.width < 8 || o.height < 8 || o.width > 8192 || o.height > 8192)
    throw Error("--size", "must be 8..8192 pixels per side");
  if (!(o.fov_deg > 1.0f && o.fov_deg < 170.0f)) throw Error("--fov", "must be in (1, 170) degrees");
  if (!(o.min_region_size > 0.0f)) throw Error("--cpv-size", "must be a positive number of metres");
  if (!(o.min_vdi_deg > 0.0f && o.min_vdi_deg <= 90.0f)) throw Error("--vdi-deg", "must be in (0, 90] degrees");
  if (!(o.max_pitch_deg > 0.0f && o.max_pitch_deg <= 90.0f)) throw Error("--max-pitch", "must be in (0, 90] degrees");
  if (!(o.max_object_share > 0.0f)) throw Error("place options", "max_object_share must be positive");
  if (!(o.near_plane > 0.0f && o.far_plane > o.near_plane)) throw Error("--near/--far", "need 0 < near < far");
  if (o.visibility_grid < 2 || o.visibility_grid > 16)
    throw Error("--visibility-grid", "must be 2..16 sample points per side, got " + std::to_string(o.visibility_grid));
  for (double f : o.fallback_bound_factors)
    if (!(f > 1.0) || !std::isfinite(f)) throw Error("--fallback-bounds", "each factor must be a number > 1");
}

nlohmann::json placeOptionsToJson(const PlaceOptions& o) {
  nlohmann::json space = nullptr;
  if (!o.view_space.empty())
    space = {{"lo", {o.view_space.lo.x, o.view_space.lo.y, o.view_space.lo.z}},
             {"hi", {o.view_space.hi.x, o.view_space.hi.y, o.view_space.hi.z}}};
  const placement::CandidateOptions& c = o.candidates;
  const impostor::LayeredOptions& l = o.layered;
  return {{"view_space", space},
          {"t_max_ms", o.t_max_ms},
          {"error_px", o.error_px},
          {"width", o.width},
          {"height", o.height},
          {"fov_deg", o.fov_deg},
          {"near_plane", o.near_plane},
          {"far_plane", o.far_plane},
          {"min_region_size", o.min_region_size},
          {"min_vdi_deg", o.min_vdi_deg},
          {"max_pitch_deg", o.max_pitch_deg},
          {"max_object_share", o.max_object_share},
          {"visibility", o.visibility},
          {"visibility_face", o.visibility_face},
          {"visibility_grid", o.visibility_grid},
          {"seed", o.seed},
          {"fallback_bound_factors", o.fallback_bound_factors},
          {"layer_tiles", o.layer_tiles},
          {"hierarchy", {{"max_levels", o.hierarchy.max_levels},
                         {"min_objects_to_split", o.hierarchy.min_objects_to_split}}},
          {"candidates", {{"shafts", c.shafts},
                          {"apex_angles", c.apex_angles},
                          {"direction_step", c.direction_step},
                          {"elevations", c.elevations},
                          {"first_distance_factor", c.first_distance_factor},
                          {"distance_steps", c.distance_steps},
                          {"drop_identical", c.drop_identical},
                          {"rectangular_cells", c.rectangular_cells},
                          {"box_leaves_only", c.box_leaves_only}}},
          {"layered", {{"texel_pixels", l.texel_pixels},
                       {"max_texture_size", l.max_texture_size},
                       {"max_layers", l.max_layers},
                       {"layer_count", l.layer_count},
                       {"bound_cracks", l.bound_cracks},
                       {"id_textures", l.id_textures},
                       {"solid_slices", l.solid_slices},
                       {"dilate_texels", l.dilate_texels}}}};
}

PlaceOptions placeOptionsFromJson(const nlohmann::json& j, const std::string& source) {
  StrictJson r(j, source, "placement option");
  PlaceOptions o;
  const nlohmann::json& space = r.at("view_space");
  if (!space.is_null()) {
    StrictJson s(space, source + ".view_space", "placement option");
    std::vector<float> lo, hi;
    s.numbers("lo", lo);
    s.numbers("hi", hi);
    s.rejectUnknown();
    if (lo.size() != 3 || hi.size() != 3) throw Error(source + ".view_space", "lo and hi need three numbers each");
    o.view_space = Box3::fromPoints(Vec3(lo[0], lo[1], lo[2]), Vec3(hi[0], hi[1], hi[2]));
  }
  r.number("t_max_ms", o.t_max_ms);
  r.number("error_px", o.error_px);
  r.number("width", o.width);
  r.number("height", o.height);
  r.number("fov_deg", o.fov_deg);
  r.number("near_plane", o.near_plane);
  r.number("far_plane", o.far_plane);
  r.number("min_region_size", o.min_region_size);
  r.number("min_vdi_deg", o.min_vdi_deg);
  r.number("max_pitch_deg", o.max_pitch_deg);
  r.number("max_object_share", o.max_object_share);
  o.visibility = r.boolean("visibility");
  r.number("visibility_face", o.visibility_face);
  // Databases placed before the grid was an option sampled the corners and the centre.
  o.visibility_grid = 2;
  if (r.has("visibility_grid")) r.number("visibility_grid", o.visibility_grid);
  r.number("seed", o.seed);
  r.numbers("fallback_bound_factors", o.fallback_bound_factors);
  // Databases placed before layers were drawn as their tiles charged whole quads.
  o.layer_tiles = r.has("layer_tiles") ? r.boolean("layer_tiles") : false;
  StrictJson h = r.object("hierarchy");
  h.number("max_levels", o.hierarchy.max_levels);
  h.number("min_objects_to_split", o.hierarchy.min_objects_to_split);
  h.rejectUnknown();
  StrictJson c = r.object("candidates");
  o.candidates.shafts = c.boolean("shafts");
  c.numbers("apex_angles", o.candidates.apex_angles);
  c.number("direction_step", o.candidates.direction_step);
  c.numbers("elevations", o.candidates.elevations);
  c.number("first_distance_factor", o.candidates.first_distance_factor);
  c.number("distance_steps", o.candidates.distance_steps);
  o.candidates.drop_identical = c.boolean("drop_identical");
  o.candidates.rectangular_cells = c.boolean("rectangular_cells");
  // Databases placed before per-cell boxes existed say nothing of them: boxes from every region then.
  o.candidates.box_leaves_only = c.has("box_leaves_only") && c.boolean("box_leaves_only");
  c.rejectUnknown();
  StrictJson l = r.object("layered");
  l.number("texel_pixels", o.layered.texel_pixels);
  l.number("max_texture_size", o.layered.max_texture_size);
  l.number("max_layers", o.layered.max_layers);
  l.number("layer_count", o.layered.layer_count);
  o.layered.bound_cracks = l.boolean("bound_cracks");
  o.layered.id_textures = l.boolean("id_textures");
  o.layered.solid_slices = l.boolean("solid_slices");
  l.number("dilate_texels", o.layered.dilate_texels);
  l.rejectUnknown();
  r.rejectUnknown();
  validate(o);
  return o;
}

}  // namespace farfield::bake
