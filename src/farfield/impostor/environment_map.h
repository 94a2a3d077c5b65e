// Layered environment-map impostors of a box view cell: the baseline of Jeschke et al. 2005, section 6, test 15 (their
// implementation of Jeschke, Wimmer and Schumann 2002, "Layered environment-map impostors"): for a view cell, what
// lies farther than a far-field distance from its centre is drawn as depth layers of a cube map around the centre, the
// rest (the near field) as geometry. It gives no frame-time guarantee by itself; eval/envmap_baseline.h picks the
// distance of each cell from the cost model, so that the comparison with the placement is at the same t_max.
//
// Frame: the capture eye c is the cell's centre. The space outside the cube |x - c|_inf < d (d: the far-field
// distance) splits into the six cube faces' frusta by the largest coordinate of x - c; in face f (axis a_f) the depth
// t = dot(x - c, a_f) is >= d. A layer is a slab t_lo <= t <= t_hi perpendicular to a_f, drawn as a quad in the plane
// t = t_m and textured with what c sees of the slab (the capture camera's near and far planes cut it out), so a point P
// of the slab is drawn at P' = c + (P - c) t_m / t. An object belongs to the far field when its bounds miss the cube;
// every other object is near field.
//
// The spacing, uniform in w = 1/(t - r) (r: the cell's half-diagonal, so every viewpoint V has |V - c| <= r): P and P'
// lie on one ray from c at distances D and D' = D t_m / t. The law of sines in the triangle V P P' gives
//   sin(angle P V P') <= |D' - D| r / (|VP| |VP'|) <= r |1/(D - r) - 1/(D' - r)|,
// and with D = t / cos(phi) (phi: the angle off the face axis) the right side grows with cos(phi), so its worst case
// is on the axis: r |1/(t - r) - 1/(t_m - r)| = r |w - w_m|. Slabs of width dw in w, with the quad at the middle of
// the slab in w, keep every point's error angle under asin(r dw / 2); dw = 2 sin(bound angle) / r keeps the bound.
// Texels: one `texel_pixels` corner pixel of the bound seen from the nearest viewpoint, at t_m - r from the plane.
//
// Each face is a LayeredPlan (impostor/layered.h) whose capture eye is c, so impostor::captureLayered, cropLayered and
// GpuLayeredImpostor capture, crop and draw it: the plan's shaft has its apex far out on the face axis (apex =
// c + L a_f, axis -a_f, min_distance L, L beyond every layer), which puts the eye at c and the quads at t_m.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/core/error_bound.h"
#include "farfield/impostor/layered.h"

namespace farfield::impostor {

struct EnvMapOptions {
  double texel_pixels = 1.0;    // as LayeredOptions::texel_pixels (never coarser than the bound)
  int max_texture_size = 1024;  // per layer side, 1..16384; a layer that would need more gets coarser texels
  int dilate_texels = 2;        // as LayeredOptions::dilate_texels
};

struct EnvMapObject {
  uint32_t id = 0;
  Box3 bounds;  // world
};

struct EnvMapFace {
  int face = 0;                   // 0..5: +x, -x, +y, -y, +z, -z
  LayeredPlan plan;               // only slabs that some object of the face meets (far to near)
  std::vector<uint32_t> objects;  // far-field objects that may show in this face's frustum, ascending
  // Per layer of plan, the face's objects whose depth range meets the slab (what a capture of that layer draws).
  std::vector<std::vector<uint32_t>> layer_objects;
};

struct EnvMapPlan {
  Box3 cell;
  Vec3 centre{0.0f};
  double far_distance = 0.0;      // d, metres
  double radius = 0.0;            // r: the cell's half-diagonal
  double slab_width_w = 0.0;      // dw, 1/metres
  double error_angle = 0.0;       // radians: asin(r dw / 2), <= the bound's angle
  bool resolution_capped = false; // a layer hit max_texture_size
  std::vector<uint32_t> near_objects;  // drawn as geometry, ascending
  std::vector<EnvMapFace> faces;       // the faces with far-field objects, in face order
  size_t layers() const;
  uint64_t texels() const;        // before cropping
  size_t bytes() const;           // the faces' LayeredPlan::bytes()
  size_t draws() const;           // one per atlas
};

// Plans the cell's environment map with far-field distance `far_distance` over `objects` (the objects that can be
// seen from the cell, e.g. its from-region visible set). Pure arithmetic, no GL; colour textures only (no id
// textures), solid slices. Throws farfield::Error naming the input for an empty or non-finite cell, a far-field
// distance not above the cell's half-diagonal (viewpoints inside the layers), an object with empty or non-finite
// bounds or id 0, a bound without pixels, and options out of range.
EnvMapPlan planEnvironmentMap(const Box3& cell, double far_distance, std::span<const EnvMapObject> objects,
                              const ErrorBound& bound, const EnvMapOptions& options = {});

// What a view of the cell draws of its environment map: the layer quads whose bounds meet `view` (a frustum from
// inside the cell, e.g. a CPV's enclosing frustum), and the frame pixels their tiles cover (LayerPlan::cover,
// planned from the slabs' objects or measured), transparent texels included,
// seen from the cell's nearest viewpoint to each quad (distance t_m - r, each quad capped at the frame) in frames of
// `frame`'s focal length: the fill the alpha test pays, as impostor::layeredFillPixels estimates a placed impostor's.
struct EnvMapLayersInView {
  size_t quads = 0;
  double fill_pixels = 0.0;
};
EnvMapLayersInView envMapLayersInView(const EnvMapPlan& plan, const Frustum& view, const ErrorBound& frame);

// The angle (radians) at viewpoint `eye` between a point P and where face `face_plan` of an environment map draws it
// (P projected from the capture eye onto the plane of P's layer); P must lie in one of the plan's slabs and in the
// face's frustum. For tests against the spacing rule.
double envMapPointError(const LayeredPlan& face_plan, const Vec3& eye, const Vec3& p);

}  // namespace farfield::impostor
