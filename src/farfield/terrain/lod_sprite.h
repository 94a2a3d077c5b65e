// LOD-sprite terrain rendering, Chen et al. 1999 section 3 (Figure 3's algorithm), with section 5's future work.
//
// Each frame: build the low-resolution LOD mesh for the camera; measure the error of the current sprite at this
// viewpoint (sprite_error.h, equation 2); when it reaches the threshold, render a new keyframe: the high-resolution
// mesh into an off-screen target whose colour is the sprite, keeping its camera (view/projection) and z-buffer. Then
// draw the low-resolution mesh: triangles whose three vertices were visible in the keyframe (equation 3,
// keyframe_visibility.h) take the sprite through the keyframe's projection, the others the original texture.
// As in the pseudocode, a keyframe's own frame is drawn the same way, from the fresh sprite.
//
// Section 5, built (both off by default, so the default is the paper's technique):
// - predict: right after a new sprite is taken into use, the next keyframe is rendered ahead, from a viewpoint
//   extrapolated linearly from the last few viewpoints to the frame where the current sprite is expected to expire
//   (predict_lead times as many frames ahead as the previous sprite lasted). From the next frame on, its mesh is
//   built (one frame), then its triangles are drawn in up to `predict_chunks` slices, one per frame (no frame pays
//   a whole keyframe; fewer slices when sprites are short-lived), then its z-buffer is read (with the CDLOD terrain,
//   gpu_high: its nodes are selected and the first slice drawn in the first frame; with gpu_low nothing is read). When
//   the current sprite's error trips, the predicted keyframe is used if its error at the current viewpoint is below
//   3/4 of the threshold and it covers the view (see reuse_coverage); otherwise a keyframe is rendered at once.
// - cache_size > 1: the most recent keyframes are kept (least recently used replaced). When the error trips, the
//   kept keyframe with the smallest error at the current viewpoint is reused if it passes the error test and
//   covers the view; otherwise a new keyframe is rendered.
// Never slower (path_choice.h): with a cost model (LodSpriteOptions::cost), each frame chooses between drawing the
// high-resolution LOD and the sprite path by their predicted costs; when the error trips and a new keyframe would
// not pay for itself over the expected sprite lifetime, the frame draws the high LOD and the error metric continues
// from a virtual keyframe at that viewpoint; once that virtual keyframe has lasted long enough for a real one to pay,
// a keyframe is taken (a "switch", before the metric trips; without switches the frames where the error trips are
// those of simulateKeyframes).
// Without a cost model every frame takes the sprite path, as the paper does.
// "Covers the view": the share of the current low-resolution triangles visible in that keyframe is at least
// reuse_coverage times the share its own low-resolution mesh had when it was rendered (a keyframe looking the other
// way passes the angular test but would texture little of the view), or at least the share visible in the sprite it
// replaces (which was drawn until now: a keyframe rendered ahead that the view turned a little away from is still
// better than a whole keyframe drawn in the frame).
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/terrain_renderer.h"
#include "farfield/image/image.h"
#include "farfield/terrain/cdlod_sprite_error.h"
#include "farfield/terrain/cost_correction.h"
#include "farfield/terrain/gpu_lod.h"
#include "farfield/terrain/keyframe_visibility.h"
#include "farfield/terrain/path_choice.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/sprite_error.h"
#include "farfield/terrain/terrain_cost.h"

namespace farfield::terrain {

// Figure 3's keyframe decisions (lines 1-5) along a camera sequence without rendering: the decision depends only on
// the keyframe's eye and the low-resolution mesh of each frame. 1 marks a keyframe. (What LodSpriteRenderer does
// with cache_size 1 and no prediction; cheap enough to sweep frame counts and thresholds.)
std::vector<uint8_t> simulateKeyframes(const QuadtreeLod& lod, const std::vector<Camera>& cameras, float low_error,
                                       double epsilon, std::vector<double>* error_px = nullptr);

// Renders one frame of a LOD mesh with the original texture (the "high" and "low" runs). Binds the target; does not
// clear it and does not wait. `scratch` keeps its allocation between frames. hole: grid points whose triangles are
// left out (removeTrianglesInside).
gpu::FrameStats renderLodFrame(const QuadtreeLod& lod, gpu::TerrainRenderer& renderer, const Camera& camera,
                               const LodSettings& settings, gpu::RenderTarget& target, LodMesh& scratch,
                               const GridRect& hole = {});

// A keyframe camera with a guard band: the same eye, direction and pixel density as `camera` drawing a frame of
// width x height, its image grown by round(margin * size) whole pixels on each side (so at its own viewpoint every
// frame pixel centre falls on a keyframe texel centre). The camera's own width and height are not used.
Camera guardBandCamera(const Camera& camera, int width, int height, float margin);

struct LodSpriteOptions {
  double epsilon = 1.0;     // error threshold, pixels (equation 2)
  float high_error = 1.0f;  // LOD threshold of keyframes, pixels
  float low_error = 4.0f;   // LOD threshold of novel frames, pixels (about 1500 triangles at 512x512, as the paper)
  VisibilityOptions visibility;
  Vec4 sky_color{0.62f, 0.74f, 0.88f, 1.0f};  // background of keyframes
  // Guard band: keyframes are rendered round(margin * width) pixels wider on each side (and likewise taller), at the
  // frame's pixel density, so that low-resolution triangles reaching a little past the frame edge, and views that
  // have moved a little, still find their vertices in the keyframe. 0 = the paper's keyframe, exactly the frame.
  float keyframe_margin = 0.1f;
  // Section 5.
  bool predict = false;
  int predict_history = 4;  // viewpoints the extrapolation uses (>= 2)
  int predict_chunks = 4;   // at most this many frames a predicted keyframe's triangles are spread over (>= 1);
                            // fewer when sprites last less than twice that
  // How far ahead, in lifetimes of the previous sprite: 1 = where the current sprite should expire; more centres the
  // next keyframe on the stretch where it will be used, so it serves views before and after it (with steady motion,
  // lead 1.25 makes sprites last about 4/3 as long; above 1.5 they would be too far ahead to take over).
  float predict_lead = 1.25f;
  // When the keyframe is rendered ahead: false = right after a sprite is taken into use, from a viewpoint
  // predict_lead lifetimes of the previous sprite ahead (the paper's suggestion); true = once the current sprite's
  // error, growing at its rate since the take or the last frame's where faster, says it will trip within about 1.5
  // times the frames it is drawn in, or has reached 3/4 of the threshold (with a cost model, slices of at most a third
  // of a sprite frame's predicted cost, at most predict_chunks of them), from where the camera will be when it is
  // ready (eye extrapolated linearly, the view direction turned at its recent angular rate), and taken as soon as it
  // is ready where it has less error than the current sprite (dropped otherwise). A short extrapolation, right on
  // curving paths; predict_lead is not used.
  bool predict_late = false;
  int cache_size = 1;       // keyframes kept (1 = only the current one, as in the paper)
  double reuse_coverage = 0.95;
  // The per-frame choice between the high LOD and the sprite path (path_choice.h); null = always the sprite path.
  // Must outlive the renderer. Its predictions are corrected by the measured times of the frames drawn, where the
  // caller reports them (LodSpriteRenderer::measured; cost_correction.h: per kind of frame, the median of measured /
  // predicted of its recent frames, taken `correction.lag` frames late, as a timer query would come).
  const TerrainCost* cost = nullptr;
  CostCorrectionOptions correction;
  int lifetime_history = 5;  // recent sprite lifetimes (real or virtual) the expected lifetime is the median of
  // Grid points whose triangles are not drawn (removeTrianglesInside; every mesh the renderer draws): ground that
  // something else draws, e.g. a city's. The error metric still counts the quadrants there.
  GridRect hole;
  // The high-resolution LOD (keyframes, predicted keyframes, high frames) drawn by the CDLOD terrain on the GPU
  // (gpu_lod.h) at high_error instead of the quadtree LOD; null = the quadtree LOD. With a cost model, the high
  // frames and keyframes are then predicted by its gpu_high model (calibrateTerrainCost with gpu_high), which it must
  // have. A predicted keyframe's nodes are drawn in slices as the quadtree's triangles are. Must outlive the renderer.
  GpuLodTerrain* gpu_high = nullptr;
  // With gpu_high: the sprite frame on the GPU too. Its low-resolution mesh is gpu_high's CDLOD selection at
  // low_error; equation 2 runs over that mesh's cells (sprite_error.h, a sample of at most error_quadrants of them);
  // equation 3 runs per vertex in the vertex shader against the keyframe's depth texture (gpu::CdlodSprite), and the
  // frame is one draw. Nothing is read back: a keyframe's depth stays on the GPU (spriteDepth() is empty) and
  // LodSpriteFrameInfo::visible_triangles is not counted. The reuse test of predicted and cached keyframes ("covers
  // the view") then counts the low-resolution CDLOD nodes whose box centre lies in the keyframe's image, with no
  // z-buffer (what the keyframe hides is still tested per vertex when drawn). With a cost model, its sprite frames are
  // predicted by the gpu_sprite model.
  bool gpu_low = false;
  size_t error_quadrants = 1024;
  // A keyframe also when the sprite is magnified by more than this on average over the metric's cells
  // (SpriteError::mean_magnification: its texels then cover more than this many pixels across, and it blurs what
  // the high LOD shows), not only when equation 2 trips; 0 = equation 2 alone, the paper's metric. Chen et al.'s
  // metric measures parallax only: on a smooth terrain approached head-on a sprite keeps theta near 0 while it is
  // magnified. Above 1.
  double max_magnification = 0.0;
};

enum class SpriteSource : uint8_t {
  Kept,       // the current sprite stays (error below the threshold)
  Fresh,      // a keyframe rendered in this frame
  Predicted,  // the keyframe rendered ahead was taken into use
  Cached,     // an earlier keyframe was reused
  None,       // no sprite: the frame drew the high-resolution LOD (path_choice.h)
};
const char* spriteSourceName(SpriteSource source);

struct LodSpriteFrameInfo {
  uint64_t frame = 0;  // the renderer's count of this frame (1, 2, ... from construction or reset): for measured()
  SpriteSource source = SpriteSource::Kept;
  double error_px = 0.0;          // error of the sprite used in this frame at this viewpoint (0 for a fresh one)
  // Error of the previous sprite at this viewpoint (what the test saw), or in the last frame where a keyframe rendered
  // ahead was taken without measuring it here (predict_late).
  double trigger_error_px = 0.0;
  double magnification = 1.0;     // the drawn sprite's mean magnification here (SpriteError::mean_magnification)
  uint64_t low_triangles = 0;
  uint64_t visible_triangles = 0;   // low-resolution triangles textured with the sprite
  uint64_t keyframe_triangles = 0;  // high-resolution triangles of a keyframe rendered in this frame
  uint64_t ahead_triangles = 0;     // triangles of the predicted keyframe drawn in this frame
  size_t ahead_slices = 0;          // its slices drawn in this frame (its last ones where a trip finished it)
  size_t quadrants = 0;             // n of equation 2
  // The per-frame choice (with LodSpriteOptions::cost; otherwise path Sprite and no predictions).
  TerrainPath path = TerrainPath::Sprite;
  bool keyframe_due = false;        // the error tripped here (or first frame): a keyframe, real or virtual
  bool switched = false;            // a keyframe taken before the virtual one tripped (its age made it pay)
  uint64_t high_triangles = 0;      // triangles of the high LOD drawn as this frame (path High)
  double predicted_high_ms = 0.0;   // path_choice.h's PathCosts for this frame (the model's, before the correction
  double predicted_sprite_ms = 0.0; // by measured frames; the choice used them corrected)
  double predicted_keyframe_ms = 0.0;
  TerrainFrameKind kind = TerrainFrameKind::Sprite;  // what the frame drew, for the correction
  double expected_lifetime = 0.0;   // frames, when a keyframe was due
};

struct LodSpriteCounters {
  size_t frames = 0;
  size_t fresh_keyframes = 0;      // rendered at once when the error tripped (or the first frame)
  size_t predicted_rendered = 0;   // predicted keyframes completed
  size_t predicted_used = 0;
  size_t predicted_discarded = 0;  // completed or started but never used
  size_t predicted_finished = 0;   // caught by the trip with at most half its slices left: those drawn at once
  size_t cache_hits = 0;
  size_t high_frames = 0;          // frames that drew the high LOD (path_choice.h)
  size_t virtual_keyframes = 0;    // error trips answered with the high LOD instead of a keyframe
  size_t switches = 0;             // keyframes taken while a virtual keyframe was still valid
  // Every high-resolution render, whatever became of it.
  size_t highResolutionRenders() const { return fresh_keyframes + predicted_rendered; }
};

class LodSpriteRenderer {
 public:
  // Needs a current context. lod and renderer must outlive this object; frames are width x height.
  LodSpriteRenderer(const QuadtreeLod& lod, gpu::TerrainRenderer& renderer, int width, int height,
                    const LodSpriteOptions& options);
  // LOD-sprite wholly on the CDLOD terrain, with no quadtree LOD (a paged terrain, paged_gpu_lod.h, has none): its
  // keyframes, high frames and sprite frames (options.gpu_low, required) are the terrain's; options.gpu_high is set
  // to it. terrain must outlive this object.
  LodSpriteRenderer(GpuLodTerrain& terrain, int width, int height, const LodSpriteOptions& options);
  ~LodSpriteRenderer();

  // Draws one frame into target (bound here; not cleared: the caller clears it to the sky colour). The camera must
  // have the size given to the constructor.
  gpu::FrameStats render(const Camera& camera, gpu::RenderTarget& target, LodSpriteFrameInfo* info = nullptr);

  // Forgets every keyframe, counter and measured correction (a new pass over a path); keeps the GPU allocations.
  void reset();
  // The measured time of frame `frame` (LodSpriteFrameInfo::frame), ms, whenever it is known: a GPU timer query read
  // late, or a harness's wall time. With a cost model, the per-frame choice and the keyframe slices are then sized by
  // the model corrected by what it got wrong (CostCorrection); without one, or for unknown frames, nothing (false).
  bool measured(uint64_t frame, double ms);
  const CostCorrection& costCorrection() const { return correction_; }

  const LodSpriteCounters& counters() const { return counters_; }
  // Equation 2's measures over the CDLOD cells (gpu_low) and what they reused.
  const CdlodSpriteError::Counters& errorCounters() const { return error_sample_.counters(); }
  const LodSpriteOptions& options() const { return options_; }
  // The current sprite's camera and colour (tests, figures); null before the first frame.
  const Camera* spriteCamera() const;
  const gpu::RenderTarget* spriteTarget() const;
  const image::DepthImage* spriteDepth() const;

 private:
  // A sprite: the keyframe's colour (the target's colour texture), its camera and z-buffer.
  struct Keyframe {
    Camera camera;        // the keyframe's camera (with the guard band)
    Camera frame_camera;  // the frame's camera it was made for
    Mat4 view_proj{1.0f};
    gpu::RenderTarget target;
    image::DepthImage depth;
    double coverage_at_creation = 1.0;  // visible share of its own low-resolution mesh (gpu_low: of its nodes)
    uint64_t last_used = 0;
    bool ready = false;
  };
  std::unique_ptr<Keyframe> takeKeyframe();
  Camera keyframeCamera(const Camera& camera) const;
  Keyframe* renderKeyframe(const Camera& camera, gpu::FrameStats& stats, LodSpriteFrameInfo& info);
  double coverage(Keyframe& keyframe);
  // "Covers the view" (above): here its share is at least reuse_coverage times its share at creation, or at least the
  // share of `replaced` (the sprite it would replace, in use until now; null: none).
  bool coversView(Keyframe& keyframe, Keyframe* replaced);
  // With gpu_low: the share of CDLOD nodes whose box centre lies in the keyframe's image.
  double nodeCoverage(std::span<const CdlodNode> nodes, const Keyframe& keyframe) const;
  // The keyframe rendered ahead from the viewpoint extrapolated `ahead` frames on, drawn in `chunks` slices.
  void schedulePrediction(const Camera& camera, float ahead, size_t chunks);
  // With predict_late: schedules it when the current sprite's error (at its age) says it trips within 1.5 times the
  // slices it needs (model: the frame's modelCosts, which size the slices; null = predict_chunks slices).
  void scheduleLatePrediction(const Camera& camera, double error_px, const PathCosts* model);
  void advancePrediction(gpu::FrameStats& stats, LodSpriteFrameInfo& info);
  // With predict_late, in a high frame of a virtual keyframe where a sprite would pay: the keyframe the switch will
  // take, scheduled if none is, and one slice of it drawn (stats: the high frame's, the slice's added).
  void renderAheadOfSwitch(const Camera& camera, gpu::FrameStats& stats, LodSpriteFrameInfo& info);
  void keep(std::unique_ptr<Keyframe> keyframe);
  // The cost model's predictions of this frame's alternatives, and the same corrected by the measured frames.
  PathCosts modelCosts(size_t low_triangles) const;
  PathCosts correctedCosts(const PathCosts& model) const;
  // Slices a keyframe rendered ahead is drawn in, each at most kSliceShare of a sprite frame (model: modelCosts).
  double slicesFor(const PathCosts& model) const;
  // Tells the correction what this frame drew (with a cost model) and returns stats.
  gpu::FrameStats finish(const gpu::FrameStats& stats, LodSpriteFrameInfo& info, LodSpriteFrameInfo* out);
  gpu::FrameStats renderHigh(const Camera& camera, gpu::RenderTarget& target, LodSpriteFrameInfo& info);

  LodSpriteRenderer(const QuadtreeLod* lod, gpu::TerrainRenderer* renderer, int width, int height,
                    const LodSpriteOptions& options);
  const QuadtreeLod* lod_;               // null on the CDLOD terrain alone
  gpu::TerrainRenderer* renderer_;       // likewise
  int width_, height_;
  LodSpriteOptions options_;
  LodSpriteCounters counters_;
  CostCorrection correction_;
  PathCosts model_costs_;  // this frame's, uncorrected
  uint64_t frame_ = 0;
  uint64_t sprite_since_ = 0;    // frame the current sprite was taken into use
  double sprite_error_at_take_ = 0.0;  // its error then (pixels; 0 for a fresh one)
  // predict_late: the current sprite's progress towards its trip (progressPx) and its error in the last frame that drew
  // it.
  double last_progress_ = 0.0;
  double last_error_px_ = 0.0;
  uint64_t last_progress_frame_ = 0;
  // Whether those are the current sprite's in the frame before this one.
  bool lastFrameDrewCurrentSprite() const {
    return last_progress_frame_ + 1 == frame_ && last_progress_frame_ >= sprite_since_;
  }
  uint64_t last_lifetime_ = 10;  // frames the previous sprite lasted
  std::vector<std::unique_ptr<Keyframe>> kept_;  // the current sprite and (with a cache) earlier ones
  std::vector<std::unique_ptr<Keyframe>> spare_;
  Keyframe* current_ = nullptr;
  std::unique_ptr<Keyframe> pending_;  // predicted keyframe in progress or ready
  LodMesh low_, high_, pending_mesh_, probe_mesh_;
  size_t pending_chunk_ = 0;   // next step of the predicted keyframe (0 = build its mesh)
  size_t pending_chunks_ = 1;  // slices it is drawn in
  size_t pending_most_ = 0;    // predict_late: at most this many (the frames left before the trip; 0: no limit)
  CdlodSelection pending_selection_, probe_selection_;  // with gpu_high: its nodes; with gpu_low: its own low mesh
  KeyframeVisibility visibility_, probe_;
  std::deque<std::pair<Vec3, Vec3>> history_;  // recent (eye, look-at)
  // The per-frame choice: the viewpoint of the last keyframe, real or virtual, and recent sprite lifetimes.
  bool anchored_ = false;
  Vec3 anchor_eye_{0.0f};
  uint64_t anchor_since_ = 0;
  std::deque<uint64_t> lifetimes_;
  // The high-resolution LOD of options_.hole for a camera into a target (bound, not cleared): the CDLOD terrain's or
  // the quadtree's (mesh: its scratch, slot: the renderer's index slot); returns the draw's counts.
  gpu::FrameStats drawHigh(const Camera& camera, gpu::RenderTarget& target, LodMesh& mesh, int slot);
  // With gpu_low: one small sprite frame drawn at construction, so that the first real one does not pay for the
  // driver making the program's code.
  void warmUpSpriteFrame();
  // With gpu_low: the frame's low-resolution selection (GpuLodTerrain::select's handle) and its triangles.
  int low_handle_ = -1;
  size_t low_triangles_ = 0;
  // Equation 2 for the frame's low-resolution mesh, the sprite seen from v1 and the frame from v2; with gpu_low its
  // sample is kept from one measure to the next (error_sample_).
  SpriteError frameError(const Vec3& v1, const Vec3& v2) const;
  mutable CdlodSpriteError error_sample_;
  // Whether a sprite with error e is due at `share` of the bounds (epsilon, and max_magnification where set).
  bool dueAt(const SpriteError& e, double beta, double share) const;
  // How far a sprite is towards its trip, in pixels of epsilon: its error, or with max_magnification the share of the
  // way its magnification has gone from 1 to the bound, times epsilon, whichever is larger (predict_late's rate).
  double progressPx(double error_px, double magnification) const;
  // A sprite frame on the GPU: CDLOD selection `handle` (GpuLodTerrain::select) for `camera` into `target`, tested
  // against and textured by keyframe `key` seen from key_camera (its size), with options_' hole and visibility.
  gpu::FrameStats drawCdlodSprite(const Camera& camera, int handle, gpu::RenderTarget& target,
                                  const Camera& key_camera, const gpu::RenderTarget& key);
  uint64_t high_triangles_frame_ = 0;  // last high-LOD triangle counts seen at the frame's and the keyframe's camera
  uint64_t high_triangles_key_ = 0;
  bool high_latest_is_key_ = false;
};

}  // namespace farfield::terrain
