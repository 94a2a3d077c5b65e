// A city as a 3D Tiles 1.1 tileset with hierarchical levels of detail whose distant levels are Farfield impostors:
// DIR/tileset.json and one .glb per tile (DIR/tiles/LEVEL_X_Y.glb).
//
// Hierarchy: a quadtree over the objects' ground positions (the centres of their world bounds in x, y). A node holding
// at most TilesOptions::leaf_objects objects, or at max_depth, is a leaf; a node with one non-empty quadrant is that
// quadrant. Each object lies in exactly one leaf, so every tile's content covers its objects once.
//   - a leaf's content is the full geometry of its objects (scene::GltfBuilder::addObjects): geometricError 0;
//   - an inner tile's content is one textured heightfield impostor of all its objects (export_tiles_heightfield.h): a
//     capture from straight above (impostor::captureView; near-orthographic, from far enough that the tallest object
//     shows at most a quarter texel of parallax), one vertex per data texel at the point it sees, simplified with
//     meshoptimizer, the captured (lit) colour as an unlit, alpha-tested texture. Refinement is REPLACE: a viewer
//     draws the coarse mesh until the error it would show exceeds its screen-space bound, then the children instead.
// Why this representation: it is Farfield's textured depth mesh (Sillion et al. 1997) taken from above, its size is
// bounded by the capture (one R x R texture and the triangles meshoptimizer keeps, whatever the number of buildings
// below), it needs no topology of the city's meshes (a simplifier cannot merge thousands of separate closed buildings,
// but the heightfield is one connected surface), and a city seen from far is seen from above. Sillion's own
// triangulation (contour, discrepancy lines, Delaunay) was tried first: its vertices on a depth step take the near
// depth, so the far side hangs in long slanted triangles and narrow gaps are bridged (13.6 m of deviation on the
// 10-block test city at 256 texels, against 3.1 m here). Its limit: walls carry the colour of the roof-edge texels, so
// oblique views of a parent tile show smeared facades until its children load.
//
// Geometric error (metres; 3D Tiles: "the error ... introduced if this tile is rendered and its children are not"):
//   g(leaf) = 0
//   g(inner) = max( delta, N * s, max over children g(child) )
// where delta is the measured two-sided distance between the tile's mesh and the city's surface seen from above at
// the capture's resolution (its roofs and ground, and the walls at its depth steps: export_tiles_deviation.h), s is
// the capture's texel size on the lowest ground of the tile, and N = bound.pixels. The mesh is simplified under
// N s / 2, then N s / 10 and N s / 50 while delta exceeds N s and each tightening lowers it by a tenth
// (meshoptimizer's error is an estimate; delta is what is written). A viewer refining by screen-space error shows a tile only from distances d >= g / theta (theta = bound.angle(), the angle of N pixels at the bound's
// smallest pixel), where its geometric deviation spans at most N pixels and each of its texels at most one pixel.
// Children never exceed their parent (the max above), as the specification requires. tileset.geometricError (nothing
// drawn) is the root box's diagonal. CesiumJS and Cesium for Unreal compare g * f / d with maximumScreenSpaceError,
// f = (viewport height / 2) / tan(fov / 2) in pixels, the frame's centre pixel; the bound is promised at its corner
// pixel, so the viewer keeps it with maximumScreenSpaceError = bound.angle() * f (TilesetStats::max_sse; written in
// the tileset's asset.extras.farfield).
//
// Frames: content is glTF (Y up); per the 3D Tiles specification a glTF tile's content is turned Y up to Z up by
// the matrix [[1,0,0,0],[0,0,-1,0],[0,1,0,0],[0,0,0,1]] (rows) before the tile's transform, so every vertex is written
// as scene::worldToGltf() times its Farfield world position (x, z, -y) and comes back as (x, y, z). Bounding volumes
// are boxes in Farfield's world frame (Z up, metres). With a georeference the root's transform is the local
// east-north-up frame at its origin (enuTransform), rotated about up by the grid convergence so that the scene's
// +y (grid north) points where it does on the Earth; without one the root has no transform (a local frame in metres).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/math.h"
#include "farfield/impostor/capture.h"
#include "farfield/scene/scene.h"

namespace farfield::store {

// Where the scene's origin lies on the WGS 84 ellipsoid.
struct GeoOrigin {
  double lon_deg = 0.0, lat_deg = 0.0;
  double height_m = 0.0;              // above the ellipsoid
  // Angle (radians, counter-clockwise seen from above) from true north to the scene's +y axis at the origin (the
  // grid convergence of a projected coordinate system); 0 for a scene whose +y is true north.
  double grid_rotation_rad = 0.0;
};

// The standard east-north-up to Earth-centred, Earth-fixed (ECEF, WGS 84) transform at the origin (column-major, as
// 3D Tiles writes it: columns east, north, up, origin), with east and north turned by grid_rotation_rad about up so
// that the scene's +x and +y map to the Earth's directions of its grid axes.
DMat4 enuTransform(const GeoOrigin& origin);
// WGS 84 geodetic (degrees, metres) to ECEF metres.
DVec3 geodeticToEcef(double lon_deg, double lat_deg, double height_m);

// Renders `objects` of the scene from `camera` with a current GL context: impostor::captureView bound to a renderer
// and the scene on the GPU (the exporter itself never touches GL).
using CaptureFn = std::function<impostor::ImpostorCapture(const Camera& camera, std::span<const uint32_t> objects)>;

struct TilesOptions {
  ErrorBound bound{2.0, 1920, 1080, degToRad(60.0)};
  size_t leaf_objects = 8;    // at most this many objects in a leaf tile (>= 1)
  int max_depth = 10;         // quadtree levels below the root at most (1..20)
  // Capture resolution of an inner tile, texels a side; 0: the bound's frame height (a tile filling the frame's
  // height then shows about one texel a pixel), clamped to 64..2048.
  int texels = 0;
  std::optional<GeoOrigin> georeference;
  std::string scene_name;     // informative, in asset.extras
};

struct TileStats {
  std::string id;             // "L_X_Y": level and quadtree cell
  std::string content;        // relative to DIR
  int level = 0;
  bool leaf = false;
  std::vector<uint32_t> objects;  // ids of the objects it stands for (a leaf: those it draws)
  size_t triangles = 0;       // of the content
  size_t bytes = 0;           // of the .glb
  double deviation_m = 0.0;   // inner: measured delta; leaf: 0
  double texel_m = 0.0;       // inner: s
  double geometric_error = 0.0;
};

struct TilesetStats {
  std::vector<TileStats> tiles;  // parents before children (depth first)
  size_t leaves = 0, inner = 0;
  int depth = 0;                 // deepest level
  size_t bytes = 0;              // tileset.json and every content file
  double root_error = 0.0;       // the root tile's geometricError
  double tileset_error = 0.0;    // tileset.geometricError
  double max_sse = 0.0;          // maximumScreenSpaceError a CesiumJS viewer at the bound's frame should use
  int texels = 0;                // the capture resolution used
};

// Writes DIR/tileset.json and DIR/tiles/*.glb for `scene` (objects with triangles; empty ones are skipped), calling
// `capture` once per inner tile, then checks the result with checkTileset (tileset_check.h) and throws if it fails.
// Creates DIR (and DIR/tiles, whose .glb files it replaces). Shows progress on stderr. Throws farfield::Error for an
// empty scene, options out of range, a directory that cannot be written (naming it), or a tileset failing its checks.
TilesetStats exportTiles(const scene::Scene& scene, const CaptureFn& capture, const std::string& dir,
                         const TilesOptions& options);

}  // namespace farfield::store
