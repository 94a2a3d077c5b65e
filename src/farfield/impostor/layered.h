// Layered impostors for a shaft view cell (Jeschke et al. 2005, sections 4 and 6.2; the lecture's "hardware assisted
// image warping" and "single vs layered"): alpha-tested textured quads perpendicular to the shaft's axis, each holding
// the part of an object cluster between two depths, spaced so that the parallax seen from the shaft stays under the
// error bound.
//
// Frame of a plan: depth z = dot(x - apex, axis), metres, growing towards the viewers. The capture eye E sits on the
// axis at the shaft's minimum distance (E = apex + min_distance * axis) and looks at the apex with a pinhole camera,
// so its near and far planes are planes of constant z: the slab of layer i is [z_lo_i, z_hi_i] and its quad lies in
// the plane z = depth_i (the slab's centre), textured with the slab's objects as E sees them, cut open by the slab's
// planes (LayeredOptions::solid_slices). layered.cpp says why a perspective capture from E and not an orthographic one
// along the axis, and derives the spacing.
//
// The promise: a point of the cluster is drawn where E's ray through it meets its layer's plane. From every viewpoint
// of the shaft the angle between the two is at most error_angle <= bound.angle() (unless the plan is layers_capped).
// Neighbouring layers show a point of their common slab boundary up to 2 * error_angle apart (in opposite directions
// from its true place), so a crack between them can be twice the bound wide; LayeredOptions::bound_cracks halves the
// spacing when that matters.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/math.h"
#include "farfield/core/shaft.h"
#include "farfield/gpu/gpu_mesh.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/texture.h"
#include "farfield/image/image.h"

namespace farfield::impostor {

struct LayeredOptions {
  // Texel size, in pixels of the bound's frame (its smallest, corner pixel), seen from the shaft's nearest viewpoint
  // to the texel's layer (layers on the far side of the cluster get larger texels); never coarser than the bound's
  // angle (a texel is at most min(texel_pixels, bound.pixels) pixels).
  double texel_pixels = 1.0;
  int max_texture_size = 1024;  // per side, 1..16384; a layer that would need more gets coarser texels
  int max_layers = 64;          // a plan that needs more keeps this many and says so (layers_capped)
  int layer_count = 0;          // > 0: exactly this many layers whatever the bound (experiments, tests); 0: from it
  bool bound_cracks = false;    // half the spacing: the crack between neighbouring layers also stays under the bound
  bool id_textures = true;      // per-texel object ids (R32UI, 4 bytes a texel more) so item buffers name objects
  // Capture with every material double-sided: a slab that cuts a closed object open shows its inside, so each layer
  // holds the object's cross-section. Without it a layer holds only the faces turned towards the capture eye, and the
  // faces other viewpoints of the shaft see (a wall along the axis, seen edge-on from the eye) are missing.
  bool solid_slices = true;
  int dilate_texels = 2;        // colour spread into the transparent texels around the data (no fringe of the
                                // clear colour under bilinear filtering); 0..16
};

struct LayerPlan {
  float z_lo = 0.0f, z_hi = 0.0f;  // the slab, metres along the axis from the apex
  float depth = 0.0f;              // the quad's plane: the slab's centre
  float half_u = 0.0f;             // the quad's half extents along LayeredPlan::right and ::up (metres)
  float half_v = 0.0f;
  int width = 0, height = 0;       // texels
  float fov_y = 0.0f;              // the capture camera's vertical field of view (radians) that images the quad
  // After cropLayered: the image is the rectangle of the captured one starting at texel (crop_x, crop_y) (row 0 at
  // the top), width x height texels; the quad, half_u x half_v, is centred offset_u along LayeredPlan::right and
  // offset_v along ::up from the axis (0 for an uncropped layer).
  int crop_x = 0, crop_y = 0;
  float offset_u = 0.0f, offset_v = 0.0f;
  // The fraction of the quad's area that is drawn (GpuLayeredImpostor draws a layer as the rectangles of its tiles
  // that hold data, layerTiles), at most 1. Planned from the cluster's parts (planLayered), an upper bound of what
  // the capture gives; measured from the images once captured (measureLayerCover); 1 without either.
  float cover = 1.0f;
};

// A rectangle of a layer's captured image, texels, row 0 at the top.
struct LayerCrop {
  int x = 0, y = 0, width = 0, height = 0;
};

struct LayeredPlan {
  Shaft shaft;
  Box3 box;                   // the cluster's bounds (world)
  Vec3 capture_eye{0.0f};     // on the axis at min_distance
  Vec3 right{1.0f, 0.0f, 0.0f}, up{0.0f, 0.0f, 1.0f};  // the capture camera's image axes (unit, world)
  Vec3 camera_up{0.0f, 0.0f, 1.0f};                     // the up vector given to the capture camera
  float z_lo = 0.0f, z_hi = 0.0f;  // the box's depth range along the axis
  double radius = 0.0;        // metres: bounds |x - apex| for every point drawn or captured (r' in layered.cpp)
  double parallax_per_metre = 0.0;  // K: the error angle (radians) per metre between a point and its layer plane
  double max_spacing = 0.0;   // metres: the widest slab the bound allows (+inf for a flat box)
  double spacing = 0.0;       // metres: the slabs' width (z_hi - z_lo) / layer count
  double error_angle = 0.0;   // radians: K * spacing / 2, the parallax bound from any viewpoint of the shaft
  double bound_angle = 0.0;   // radians: bound.angle()
  bool layers_capped = false; // the bound needed more than max_layers: error_angle > bound_angle
  double texel_angle = 0.0;   // radians: the largest texel seen from the nearest viewpoint of its layer
  bool resolution_capped = false;  // a layer hit max_texture_size: texel_angle exceeds the wanted one
  bool id_textures = true;
  int dilate_texels = 2;
  bool solid_slices = true;
  std::vector<LayerPlan> layers;  // far to near (increasing depth)
  // The layers packed into texture atlases (shelves, tallest layers first, kAtlasPadding texels apart, at most
  // kAtlasSide texels a side unless a layer alone is larger): one texture and one draw call per atlas on the GPU.
  struct AtlasSpot {
    uint32_t atlas = 0;
    int x = 0, y = 0;  // the layer image's top-left texel in its atlas
  };
  std::vector<AtlasSpot> atlas_spots;  // per layer
  std::vector<IVec2> atlas_sizes;      // per atlas, texels

  // Estimates before generation (the placement optimiser's memory and render cost).
  uint64_t texels = 0;             // sum of the layers' width * height
  size_t texture_bytes = 0;        // colour (+ ids) atlas textures
  size_t mesh_bytes = 0;           // quads' vertex and index buffers (one quad a layer; measureLayerCover: the tiles')
  size_t bytes() const { return texture_bytes + mesh_bytes; }
  uint32_t quads() const { return uint32_t(layers.size()); }
  uint32_t draws() const { return uint32_t(atlas_sizes.size()); }  // draw calls: one per atlas
  // Pixels of the bound's frame the quads cover (transparent texels included: the fill-rate cost of an alpha test)
  // from the nearest viewpoint on the axis, each quad capped at the frame; the drawn part of it (LayerPlan::cover) is
  // what impostor::layeredFillPixels counts.
  double fill_pixels = 0.0;

  bool keepsBound() const { return !layers_capped && error_angle <= bound_angle; }
  bool cropped = false;  // cropLayers was applied: the layers are parts of the captured images
};

// Plans the layers of the cluster `box` for the viewpoints of `shaft` under `bound`. Pure arithmetic, no GL. With the
// boxes of the cluster's parts (its objects' world bounds, inside `box`), each layer's cover is planned: the tiles
// (layerTiles) that the parts cut by its slab can reach, seen from the capture eye, summed over the parts and capped
// at 1, so that it bounds the cover the capture measures. Throws farfield::Error naming the input for an empty or
// non-finite box or part, a shaft that is not valid (see Shaft::make) or whose minimum distance does not clear the
// cluster (min_distance <= radius: viewpoints inside or next to it), a bound that fails ErrorBound::validate or has
// no pixels, and options out of range.
LayeredPlan planLayered(const Box3& box, const Shaft& shaft, const ErrorBound& bound,
                        const LayeredOptions& options = {}, std::span<const Box3> parts = {});

struct Layer {
  image::ColorImage color;  // RGBA, alpha 255 where the slab's objects cover the texel, 0 elsewhere
  image::IdImage ids;       // object ids (0 = none); empty without plan.id_textures
  size_t data_texels = 0;   // covered texels
  double render_ms = 0.0;
};

struct LayeredImpostor {
  LayeredPlan plan;
  std::vector<Layer> layers;  // as plan.layers
  double capture_ms = 0.0;
  size_t cpuBytes() const;    // the images' pixels
};

// Renders the objects `object_ids` (1-based, at least one) of `scene` once per layer of `plan`, clipped to the layer's
// slab by the capture camera's near and far planes. Needs a current context. Throws farfield::Error for an empty id
// list, an id the scene does not have, an object whose bounds leave plan.box, or a plan without layers.
LayeredImpostor captureLayered(gpu::Renderer& renderer, const gpu::GpuScene& scene,
                               std::span<const uint32_t> object_ids, const LayeredPlan& plan);

// The plan with layer i cut to crops[i], a rectangle of its captured image (plan.layers[i].width x height, the plan
// not cropped yet): each quad shrinks to its rectangle and moves with it, the atlases are packed again and texels and
// texture_bytes counted again (fill_pixels stays the estimate of the whole quads: an upper bound; a layer's cover
// grows with the cut so that it bounds the same area, capped at 1). Throws
// farfield::Error naming the layer for a crop count other than the layer count, an empty crop, a crop outside its
// image, or a plan already cropped.
void cropLayers(LayeredPlan& plan, std::span<const LayerCrop> crops);

// The rectangle of the layer's texels that are not transparent black or carry an object id, grown by one texel on
// every side and clamped to the image: outside it every texel is transparent black with id 0, as is its border ring,
// which the atlas's edge clamp repeats. A 1x1 rectangle at (0, 0) for a layer without data.
LayerCrop dataCrop(const Layer& layer);

// The impostor with every layer cut to its dataCrop: the same image from every viewpoint (what is dropped is
// transparent black, and the texels that bilinear filtering and the edge clamp now read at a cut are too), fewer
// texels, and the layers' cover measured (measureLayerCover). The layers' data_texels and render_ms are kept. Throws
// farfield::Error for an impostor whose images do not match its plan or whose plan is already cropped.
LayeredImpostor cropLayered(const LayeredImpostor& impostor);

// Tiles: a layer is drawn as the tiles of kLayerTile x kLayerTile texels of its captured image (aligned to the
// captured image's texel (0, 0), so to (crop_x, crop_y) in a cropped one) that hold a texel with alpha > 0 or lie
// within one texel of one, merged into rectangles (runs along a row, equal runs of consecutive rows joined). Every
// fragment of a layer's quad outside them samples, bilinearly, only transparent texels, which the alpha test discards:
// the tiles draw the quad's image and shade only near its data (a layer holds 10-70 % of its rectangle).
inline constexpr int kLayerTile = 8;

// The rectangles, in texels of `color` (row 0 at the top), of its tiles with data, the grid's origin at
// (-origin.x, -origin.y) of the image (a cropped layer's crop_x, crop_y). Each texel lies in at most one rectangle.
std::vector<LayerCrop> layerTiles(const image::ColorImage& color, IVec2 origin = IVec2(0));

// The cover of layer `layer` of an uncropped plan made by planLayered (or laid out alike: impostor/environment_map.h)
// from the boxes of what its slab may hold: planLayered's bound. Pure arithmetic.
float plannedLayerCover(const LayeredPlan& plan, size_t layer, std::span<const Box3> parts);

// Sets each layer's cover to its tiles' area over its image's, and mesh_bytes to their rectangles': what
// GpuLayeredImpostor draws. Throws farfield::Error for an impostor whose images do not match its plan.
void measureLayerCover(LayeredImpostor& impostor);

// Every layer's cover set to 1: the fill charged over the whole quads (placement and calibration for comparisons with
// drawing the whole quads; PlaceOptions::layer_tiles, LayeredCalibrateOptions::layer_tiles).
void coverWholeQuads(LayeredPlan& plan);

inline constexpr int kAtlasSide = 4096;
inline constexpr int kAtlasPadding = 2;  // texels around each layer image, its edge texels repeated (clamp to edge)
// A layer quad's (or tile rectangle's) vertex and index buffers: GpuMesh's interleaved position, normal and uv floats
// (32 bytes a vertex) and 32-bit indices.
inline constexpr size_t kLayerQuadBytes = 4 * 8 * sizeof(float) + 6 * sizeof(uint32_t);

// How GpuLayeredImpostor draws a layer: as its tiles (layerTiles), or as its whole quad (for comparisons: the same
// image, every texel shaded).
enum class LayerDraw { Tiles, WholeQuads };

// Packs plan.layers into atlases (sets atlas_spots and atlas_sizes; texture_bytes is the caller's): shelves, tallest
// layers first, at most kAtlasSide a side unless a layer alone is larger. planLayered and cropLayers call it; a plan
// made elsewhere (impostor/environment_map.h) calls it once its layers are set.
void packAtlases(LayeredPlan& plan);

// A layered impostor's atlases made on the CPU, ready to upload: per atlas (LayeredPlan::atlas_sizes) its image (and
// id image, with id textures) holding its layers' images and their padding, and the mesh of its layers' tile
// rectangles (LayerDraw::Tiles; whole quads with LayerDraw::WholeQuads; normal = the axis, uvs into the atlas). No GL:
// a reader thread makes them ahead of the frame that uploads them (runtime/walkthrough_placed.cpp).
struct LayeredAtlases {
  std::vector<image::ColorImage> colors;
  std::vector<image::IdImage> ids;  // empty without id textures
  std::vector<scene::Mesh> meshes;
  uint32_t quads = 0;       // layers
  uint32_t rectangles = 0;  // quads drawn: tile rectangles, or one per layer
  uint64_t cpuBytes() const;  // the images' texels and the meshes' vertex and index bytes
};
LayeredAtlases packLayeredAtlases(const LayeredImpostor& impostor, LayerDraw draw = LayerDraw::Tiles);

// The layers on the GPU: per atlas one texture (and id texture) and one mesh (LayeredAtlases), with an unlit,
// double-sided material: one draw call per atlas. The renderer's alpha test cuts out texels with alpha below 0.5 and
// its depth test composes the layers (and any geometry around them), so the draw order does not change the image.
// Needs a current context. Movable; draw items point into it.
class GpuLayeredImpostor {
 public:
  explicit GpuLayeredImpostor(const LayeredImpostor& impostor, LayerDraw draw = LayerDraw::Tiles);  // packs, uploads
  explicit GpuLayeredImpostor(const LayeredAtlases& atlases);  // uploads
  GpuLayeredImpostor(GpuLayeredImpostor&&) noexcept = default;
  GpuLayeredImpostor& operator=(GpuLayeredImpostor&&) noexcept = default;

  // Appends one item per atlas; object_id is written where a layer has no id texture.
  void appendDrawItems(std::vector<gpu::DrawItem>& out, uint32_t object_id = 0) const;
  uint32_t quads() const { return quads_; }           // layers
  uint32_t rectangles() const { return rectangles_; } // quads drawn: tile rectangles, or one per layer
  uint32_t draws() const { return uint32_t(meshes_.size()); }
  size_t gpuBytes() const;  // measured: the textures' and buffers' sizes

 private:
  std::vector<gpu::GpuMesh> meshes_;
  std::vector<std::unique_ptr<gpu::Texture>> textures_, id_textures_;
  std::vector<std::unique_ptr<gpu::GpuMaterial>> materials_;
  uint32_t quads_ = 0;
  uint32_t rectangles_ = 0;
};

}  // namespace farfield::impostor
