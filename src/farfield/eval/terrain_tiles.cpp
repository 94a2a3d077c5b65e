// The tiled-terrain experiment (issue 18; see terrain_tiles.h).
#include "farfield/eval/terrain_tiles.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/eval/bench.h"
#include "farfield/eval/terrain_paths.h"
#include "farfield/eval/terrain_tiles_sprite.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/metrics.h"
#include "farfield/image/png_io.h"
#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/paged_terrain.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/terrain_data.h"
#include "farfield/terrain/tile_cache.h"
#include "farfield/terrain/paged_gpu_lod.h"
#include "farfield/terrain/tile_pager.h"
#include "farfield/terrain/tile_sprites.h"
#include "farfield/terrain/tiled_lod.h"

namespace farfield::eval {
namespace {

namespace fs = std::filesystem;

const Vec4 kSky{0.62f, 0.74f, 0.88f, 1.0f};  // the terrain bench's sky (terrain_modes.h)

// Resident set of this process, bytes (Linux; 0 elsewhere).
size_t residentSetBytes() {
  std::ifstream in("/proc/self/statm");
  size_t pages = 0, resident = 0;
  if (!(in >> pages >> resident)) return 0;
  return resident * size_t(sysconf(_SC_PAGESIZE));
}

void writeFile(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw Error(file.string(), "cannot write");
}

// The process's peak resident set, bytes (VmHWM; Linux; 0 elsewhere).
size_t peakResidentSetBytes() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return size_t(std::stoull(line.substr(6))) * 1024;
  return 0;
}

double mib(size_t bytes) { return double(bytes) / (1024.0 * 1024.0); }

struct FrameRow {
  size_t triangles = 0;
  terrain::TiledLodFrame tiles;
  size_t resident = 0, loads = 0, evictions = 0;
  double ms = 0.0;
  int check = -1;  // -1 not checked, 0 same, 1 differs
  // With render: the frame drawn from the patches (LOD, tile reads, patch loads, draw, to the GPU's end; also in
  // ms, which is then that frame), its triangles, the patches made for it, the patches' GPU bytes after it.
  double frame_ms = 0.0;
  double own_ms = -1.0;  // of it, in Farfield's own code (wall less the time in GL calls); -1 uncounted
  size_t drawn_triangles = 0, patch_loads = 0, gpu_bytes = 0;
  terrain::TileSpriteFrame sprites;
};

}  // namespace

TerrainTilesResult runTerrainTiles(const TerrainTilesOptions& o) {
  if (o.frames < 2) throw Error("--frames", "need at least 2 frames");
  if (!(o.budget_mb > 0.0)) throw Error("--budget-mb", "must be positive");
  if (o.tile_blocks < 1) throw Error("--tile-blocks", "must be at least 1");
  if (!(o.pixel_error > 0.0f)) throw Error("--pixel-error", "must be positive");
  if (!(o.max_magnification == 0.0 || o.max_magnification > 1.0))
    throw Error("--max-magnification", "must be above 1 (0: not bounded)");
  const Stopwatch total;
  const fs::path out(o.out_dir);
  fs::create_directories(out);
  const std::string cache_path = o.cache.empty() ? (out / "terrain.tiles").string() : o.cache;

  // A DEM file is read window by window into the cache and never held whole, unless the whole grid's LOD is
  // asked for (the check, the sprites per tile); a fractal is generated whole, written, then dropped.
  const bool streamed = !terrain::isFractalSpec(o.dem) && o.check_stride == 0 && o.sprite_tile_cells == 0;
  std::unique_ptr<terrain::Heightfield> hf;
  std::optional<terrain::DemReader> dem;
  if (streamed) {
    dem.emplace(o.dem);
  } else {
    hf = std::make_unique<terrain::Heightfield>(terrain::cropForBlocks(terrain::loadHeightfield(o.dem), o.block));
  }
  const std::string source = hf ? hf->source : dem->header().source;
  double write_seconds = 0.0;
  if (!o.reuse_cache) {
    const Stopwatch w;
    if (hf) terrain::TileCache::write(*hf, o.block, o.tile_blocks, cache_path);
    else terrain::TileCache::write(*dem, o.block, o.tile_blocks, cache_path);
    write_seconds = w.seconds();
  }
  dem.reset();
  const terrain::TileCache cache(cache_path);
  if (hf && (cache.layout().width != hf->width || cache.layout().height != hf->height))
    throw Error(cache_path, "tile cache does not match " + source + " at block " + std::to_string(o.block));
  if (cache.layout().block != o.block)
    throw Error(cache_path, "tile cache has LOD blocks of " + std::to_string(cache.layout().block) + " cells, not " +
                                std::to_string(o.block));
  const int grid_w = cache.layout().width, grid_h = cache.layout().height;
  // The flythrough is planned on the grid, or on the cache's overview (at most about 2,049 x 2,049 points).
  int overview_step = 1;
  while (!hf && overview_step < o.block / 2 &&
         uint64_t(grid_w / overview_step) * uint64_t(grid_h / overview_step) > (uint64_t(2049) * 2049))
    overview_step *= 2;
  const terrain::Heightfield plan = hf ? terrain::Heightfield() : cache.overview(overview_step);
  const terrain::Heightfield& planned_on = hf ? *hf : plan;
  terrain::FlythroughOptions fo;
  fo.frames = o.frames;
  fo.clearance = o.clearance;
  const gen::CameraPath path = flythroughCameraPath(planned_on, fo);
  const ClipPlanes clip = terrainClipPlanes(planned_on, path);
  std::unique_ptr<terrain::QuadtreeLod> whole;
  if (o.check_stride > 0 || o.sprite_tile_cells > 0) whole = std::make_unique<terrain::QuadtreeLod>(*hf, o.block);
  else hf.reset();
  const size_t rss_after_drop = residentSetBytes();

  terrain::TilePager pager(cache, size_t(o.budget_mb * 1024.0 * 1024.0));
  terrain::LodSettings settings;
  settings.pixel_error = o.pixel_error;
  std::vector<FrameRow> rows;
  terrain::LodMesh mesh, check;
  TerrainTilesResult result;
  size_t rss_peak = rss_after_drop;
  // Drawing: a context, a target, and the patches paged under their budget.
  std::unique_ptr<gpu::RenderTarget> target;
  double cdlod_prepare_seconds = 0.0;
  std::unique_ptr<terrain::PagedTerrainRenderer> paged;
  std::unique_ptr<terrain::PagedGpuLodTerrain> cdlod;
  if (!o.gpu_lod && !o.render) throw Error("--cpu-lod", "draws frames: needs --render");
  if (o.lod_sprite && !(o.render && o.gpu_lod))
    throw Error("--lod-sprite", "draws LOD-sprite over the CDLOD terrain: needs --render without --cpu-lod");
  std::unique_ptr<PagedSpriteRun> sprite_run;
  std::unique_ptr<gpu::RenderTarget> sprite_target;
  std::vector<PagedSpriteFrame> sprite_frames;
  std::vector<double> cdlod_ms;
  if (o.render) {
    if (!(o.gpu_budget_mb > 0.0)) throw Error("--gpu-budget-mb", "must be positive");
    gpu::sharedHeadlessContext().makeCurrent();
    gpu::installGlCounters();  // Farfield's own CPU time per frame
    target = std::make_unique<gpu::RenderTarget>(o.width, o.height);
    if (o.prefetch_frames < 0) throw Error("--prefetch-frames", "must be 0 or more");
    if (o.gpu_lod) {
      const Stopwatch prepare;
      terrain::PagedGpuLodOptions po;
      po.lod.patch_cells = o.patch_cells;
      po.gpu_budget_bytes = size_t(o.gpu_budget_mb * 1024.0 * 1024.0);
      po.prefetch_frames = o.prefetch_frames;
      po.keep_heights = o.lod_sprite;  // LOD-sprite's error metric reads the held pages' heights
      cdlod = std::make_unique<terrain::PagedGpuLodTerrain>(cache, po);
      cdlod_prepare_seconds = prepare.seconds();
      if (o.lod_sprite) {
        std::vector<Camera> cameras;
        for (size_t f = 0; f < path.frames.size(); ++f)
          cameras.push_back(path.camera(f, o.width, o.height, clip.near_plane, clip.far_plane));
        PagedSpriteOptions so;
        so.epsilon = o.epsilon;
        so.pixel_error = o.pixel_error;
        so.low_error = o.low_error;
        so.predict = o.lod_sprite_predict;
        so.max_magnification = o.max_magnification;
        so.cost_correction = o.cost_correction;
        sprite_run = std::make_unique<PagedSpriteRun>(*cdlod, cameras, so);
        sprite_target = std::make_unique<gpu::RenderTarget>(o.width, o.height);
        std::fprintf(stderr, "LOD-sprite: cost model fitted on the path's views in %.1f s\n",
                     sprite_run->calibrationSeconds());
      }
    } else {
      paged = std::make_unique<terrain::PagedTerrainRenderer>(pager, size_t(o.gpu_budget_mb * 1024.0 * 1024.0),
                                                              o.prefetch_frames);
    }
    fs::create_directories(out / "frames");
  }
  std::unique_ptr<terrain::TileSprites> tile_sprites;
  if (o.sprite_tile_cells > 0)
    tile_sprites = std::make_unique<terrain::TileSprites>(
        *whole, terrain::TileSpriteOptions{o.sprite_tile_cells, o.epsilon, o.low_error, o.pixel_error});
  for (size_t f = 0; f < path.frames.size(); ++f) {
    const Camera camera = path.camera(f, o.width, o.height, clip.near_plane, clip.far_plane);
    FrameRow row;
    if (cdlod) {
      // The CDLOD frame: the selection, the pages it needs (read at once if missing), the draw, to the GPU's end.
      target->clear(kSky);
      const gpu::GlCounters before = gpu::glCounters();
      const Stopwatch draw;
      // With LOD-sprite, the pages are read ahead after the timed frame (both frames then leave it out).
      const terrain::PagedGpuLodFrame cf = sprite_run ? cdlod->draw(camera, o.pixel_error, *target)
                                                      : cdlod->drawFrame(camera, o.pixel_error, *target);
      cdlod->finish();
      row.frame_ms = row.ms = draw.milliseconds();
      row.own_ms = ownCpuMs(row.frame_ms, before);
      if (sprite_run) {
        cdlod_ms.push_back(row.frame_ms);
        cdlod->prefetch(camera, o.pixel_error);
        PagedSpriteFrame sf = sprite_run->draw(camera, *sprite_target);
        if (o.psnr_stride > 0 && f % o.psnr_stride == 0)
          sf.psnr_vs_high = std::min(image::psnr(sprite_target->readColor(), target->readColor()), kPsnrCapDb);
        if (o.sample_stride > 0 && f % o.sample_stride == 0) {
          // The LOD-sprite frame and its difference from the CDLOD frame (frame_NNNNN.png).
          char name[48];
          const image::ColorImage sprite_image = sprite_target->readColor();
          std::snprintf(name, sizeof name, "lod_sprite_%05zu.png", f);
          image::writePng((out / "frames" / name).string(), sprite_image);
          std::snprintf(name, sizeof name, "lod_sprite_diff_%05zu.png", f);
          image::writePng((out / "frames" / name).string(), image::diffHeatmap(target->readColor(), sprite_image));
        }
        sprite_frames.push_back(sf);
      }
      row.triangles = row.drawn_triangles = cf.draw.triangles;
      row.patch_loads = cf.page_loads;
      row.gpu_bytes = cdlod->stats().pages * cdlod->pageBytes();  // the pages held
      if (o.sample_stride > 0 && f % o.sample_stride == 0) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%05zu.png", f);
        image::writePng((out / "frames" / name).string(), target->readColor());
      }
    } else if (paged) {
      // The frame as a renderer draws it: the LOD per tile, the tiles read (or taken from the prefetch), the
      // patches made, the draw, to the GPU's end.
      target->clear(kSky);
      const Stopwatch draw;
      const terrain::PagedTerrainFrame pf = paged->draw(camera, settings, *target);
      paged->finish();
      row.frame_ms = row.ms = draw.milliseconds();
      row.tiles = pf.tiles;
      row.triangles = row.drawn_triangles = pf.draw.triangles;
      row.patch_loads = pf.patch_loads;
      row.gpu_bytes = paged->stats().gpu_bytes;
      if (o.sample_stride > 0 && f % o.sample_stride == 0) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%05zu.png", f);
        image::writePng((out / "frames" / name).string(), target->readColor());
      }
    } else {
      const Stopwatch sw;
      terrain::buildTiledLod(pager, camera, settings, mesh, &row.tiles);
      row.ms = sw.milliseconds();
      row.triangles = mesh.triangleCount();
    }
    row.resident = pager.stats().resident_bytes;
    row.loads = pager.stats().loads;
    row.evictions = pager.stats().evictions;
    if (o.check_stride > 0 && f % o.check_stride == 0) {
      terrain::LodSettings all = settings;
      all.cull = false;
      buildTiledLod(pager, camera, all, mesh);
      whole->build(camera, all, check);
      std::vector<uint32_t> a = mesh.indices, b = check.indices;
      // Same triangles, whatever their order (each triangle's indices keep their rotation: both start at the
      // triangle's right angle).
      auto sorted = [](std::vector<uint32_t>& v) {
        std::vector<std::array<uint32_t, 3>> t(v.size() / 3);
        for (size_t i = 0; i < t.size(); ++i) t[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
        std::sort(t.begin(), t.end());
        return t;
      };
      row.check = sorted(a) == sorted(b) ? 0 : 1;
      result.check_mismatches += size_t(row.check);
    }
    if (tile_sprites) row.sprites = tile_sprites->advance(camera);
    if (f % 50 == 0) rss_peak = std::max(rss_peak, residentSetBytes());
    rows.push_back(row);
  }
  const terrain::TilePagerStats& st = pager.stats();

  std::ostringstream csv;
  csv << "frame,triangles,tiles_in_view,tiles_culled,full_resolution_tiles,coarsest_step,resident_bytes,loads,"
         "evictions,lod_ms,check,sprite_tiles_in_view,sprite_tiles_refreshed,sprite_tiles_triangles,"
         "whole_keyframe,whole_keyframe_triangles,frame_ms,drawn_triangles,patch_loads,patch_gpu_bytes\n";
  struct {
    size_t tile_refreshes = 0, tile_views = 0, whole_keyframes = 0;
    uint64_t tile_triangles = 0, whole_triangles = 0;
  } sprite;
  size_t max_tri = 0, sum_tri = 0;
  double sum_ms = 0.0;
  std::vector<double> ms;
  for (size_t f = 0; f < rows.size(); ++f) {
    const FrameRow& r = rows[f];
    csv << f << ',' << r.triangles << ',' << r.tiles.tiles_in_view << ',' << r.tiles.tiles_culled << ','
        << r.tiles.full_resolution_tiles << ',' << r.tiles.coarsest_step << ',' << r.resident << ',' << r.loads << ','
        << r.evictions << ',' << r.ms << ',' << r.check << ',' << r.sprites.tiles_in_view << ','
        << r.sprites.tiles_refreshed << ',' << r.sprites.refreshed_triangles << ',' << int(r.sprites.whole_keyframe)
        << ',' << r.sprites.whole_triangles << ',' << r.frame_ms << ',' << r.drawn_triangles << ','
        << r.patch_loads << ',' << r.gpu_bytes << '\n';
    sprite.tile_refreshes += r.sprites.tiles_refreshed;
    sprite.tile_views += r.sprites.tiles_in_view;
    sprite.tile_triangles += r.sprites.refreshed_triangles;
    sprite.whole_keyframes += r.sprites.whole_keyframe ? 1 : 0;
    sprite.whole_triangles += r.sprites.whole_triangles;
    max_tri = std::max(max_tri, r.triangles);
    sum_tri += r.triangles;
    sum_ms += r.ms;
    ms.push_back(r.ms);
  }
  std::sort(ms.begin(), ms.end());
  writeFile(out / "tiles_frames.csv", csv.str());
  const double mean_tri = double(sum_tri) / double(rows.size());
  size_t full_bytes = 0;
  for (int ty = 0; ty < cache.layout().tilesY(); ++ty)
    for (int tx = 0; tx < cache.layout().tilesX(); ++tx) full_bytes += cache.residentBytes(tx, ty, 1);

  nlohmann::ordered_json j;
  j["terrain"] = source;
  j["grid"] = {grid_w, grid_h};
  j["block"] = o.block;
  j["tile_blocks"] = o.tile_blocks;
  j["tiles"] = {cache.layout().tilesX(), cache.layout().tilesY()};
  j["cache_file"] = cache_path;
  j["cache_bytes"] = fs::file_size(cache_path);
  j["cache_write_seconds"] = write_seconds;
  j["all_tiles_full_resolution_bytes"] = full_bytes;
  j["budget_bytes"] = pager.budget();
  j["peak_resident_bytes"] = st.peak_resident_bytes;
  j["loads"] = st.loads;
  j["evictions"] = st.evictions;
  j["hits"] = st.hits;
  j["requests"] = st.requests;
  j["bytes_loaded"] = st.bytes_loaded;
  j["load_seconds"] = st.load_seconds;
  j["frames"] = rows.size();
  j["pixel_error"] = o.pixel_error;
  j["triangles_mean"] = mean_tri;
  j["triangles_max"] = max_tri;
  j["lod_ms_mean"] = sum_ms / double(rows.size());
  j["lod_ms_median"] = ms[ms.size() / 2];
  j["process_rss_after_dropping_heightfield"] = rss_after_drop;
  j["process_rss_peak_during_flythrough"] = rss_peak;
  j["streamed"] = streamed;
  j["overview_step"] = overview_step;  // 1 where the flythrough was planned on the grid itself
  j["process_peak_rss"] = peakResidentSetBytes();
  j["checked_frames"] = o.check_stride ? (rows.size() + o.check_stride - 1) / o.check_stride : 0;
  j["check_mismatches"] = result.check_mismatches;
  if (tile_sprites) {
    j["sprite_tile_cells"] = o.sprite_tile_cells;
    j["epsilon"] = o.epsilon;
    j["low_error"] = o.low_error;
    j["tile_sprite_refreshes"] = sprite.tile_refreshes;
    j["tile_sprite_refresh_fraction"] = double(sprite.tile_refreshes) / double(std::max<size_t>(sprite.tile_views, 1));
    j["tile_sprite_keyframe_triangles"] = sprite.tile_triangles;
    j["whole_keyframes"] = sprite.whole_keyframes;
    j["whole_keyframe_fraction"] = double(sprite.whole_keyframes) / double(rows.size());
    j["whole_keyframe_triangles"] = sprite.whole_triangles;
  }
  std::string render_md;
  // The drawn frames' times (sorted) and triangles, for either renderer's summary.
  std::vector<double> fms;
  size_t drawn_max = 0, drawn_sum = 0;
  double fsum = 0.0;
  for (const FrameRow& r : rows) {
    fms.push_back(r.frame_ms);
    fsum += r.frame_ms;
    drawn_max = std::max(drawn_max, r.drawn_triangles);
    drawn_sum += r.drawn_triangles;
  }
  std::sort(fms.begin(), fms.end());
  if (cdlod) {
    const terrain::PagedGpuLodStats& cs = cdlod->stats();
    // Pages read in the flight's frames (the LOD-sprite run's calibration, before the flight, reads some too).
    size_t in_frames = 0;
    for (const FrameRow& r : rows) in_frames += r.patch_loads;
    size_t over_twice = 0;
    for (double v : fms) over_twice += v > 2.0 * fms[fms.size() / 2] ? 1 : 0;
    std::vector<double> own;
    for (const FrameRow& r : rows) own.push_back(r.own_ms);
    const nlohmann::ordered_json own_cpu = ownCpuSummary(own);
    const double own_median = own_cpu["median"], own_p95 = own_cpu["p95"];
    // What a page costs its thread (read, texels, mips), over every page made by either thread.
    const size_t pages_made = cs.page_loads + cs.prefetched;
    const double page_ms = pages_made > 0 ? 1000.0 * cs.load_seconds / double(pages_made) : 0.0;
    j["render"] = {{"lod", "cdlod"},
                   {"frame_ms_mean", fsum / double(fms.size())},
                   {"frame_ms_median", fms[fms.size() / 2]},
                   {"frame_ms_p99", fms[std::min(fms.size() - 1, fms.size() * 99 / 100)]},
                   {"frame_ms_max", fms.back()},
                   {"frames_over_twice_the_median", over_twice},
                   {"own_cpu_ms", own_cpu},
                   {"triangles_mean", double(drawn_sum) / double(rows.size())},
                   {"triangles_max", drawn_max},
                   {"prepare_seconds", cdlod_prepare_seconds},
                   {"overview_step", cdlod->overviewStep()},
                   {"page_layers", cdlod->pageLayers()},
                   {"pages_peak", cs.peak_pages},
                   {"page_loads_waited_for", in_frames},
                   {"page_loads_before_the_flight", cs.page_loads - in_frames},
                   {"pages_prefetched", cs.prefetched},
                   {"prefetch_hits", cs.prefetch_hits},
                   {"page_evictions", cs.evictions},
                   {"page_seconds", cs.load_seconds},
                   {"page_ms_mean", page_ms},
                   {"gpu_bytes", cdlod->gpuBytes()},
                   {"prefetch_frames", o.prefetch_frames}};
    char line[704];
    std::snprintf(line, sizeof line,
                  "\ndrawn by the CDLOD terrain paged from the cache: frame %.2f ms mean, %.2f median, %.2f p99, "
                  "%.2f max (selection, pages waited for, draw, to the GPU's end); %zu frames over twice the "
                  "median; Farfield's own CPU time %.3f ms median, %.3f p95; %.0f triangles mean, %zu max; pages: %d "
                  "layers (%.0f MiB), %zu held at most, %zu read "
                  "in frames, %zu read ahead %d frames (%zu used), %zu evictions, %.1f s reading (%.0f ms a page); "
                  "node data and overview made in %.1f s\n",
                  fsum / double(fms.size()), fms[fms.size() / 2], double(j["render"]["frame_ms_p99"]), fms.back(),
                  over_twice, own_median, own_p95, double(drawn_sum) / double(rows.size()), drawn_max,
                  cdlod->pageLayers(),
                  mib(cdlod->gpuBytes()), cs.peak_pages, in_frames, cs.prefetched, o.prefetch_frames,
                  cs.prefetch_hits, cs.evictions, cs.load_seconds, page_ms, cdlod_prepare_seconds);
    render_md = line;
    if (sprite_run) {
      j["render"]["lod_sprite"] = sprite_run->summary(sprite_frames, cdlod_ms, own);
      render_md += PagedSpriteRun::markdown(j["render"]["lod_sprite"]);
      std::ostringstream sc;
      sc << "frame,cdlod_ms,lod_sprite_ms,cdlod_own_cpu_ms,lod_sprite_own_cpu_ms,path,source,triangles,error_px,"
            "magnification,page_loads,ahead_triangles,ahead_slices,keyframe_triangles,psnr_vs_cdlod\n";
      for (size_t f = 0; f < sprite_frames.size(); ++f) {
        const PagedSpriteFrame& sf = sprite_frames[f];
        sc << f << ',' << cdlod_ms[f] << ',' << sf.ms << ',' << rows[f].own_ms << ',' << sf.own_ms << ','
           << (sf.info.path == terrain::TerrainPath::Sprite ? "sprite" : "high") << ','
           << terrain::spriteSourceName(sf.info.source) << ',' << sf.triangles << ',' << sf.info.error_px << ','
           << sf.info.magnification << ',' << sf.page_loads << ',' << sf.info.ahead_triangles << ','
           << sf.info.ahead_slices << ',' << sf.info.keyframe_triangles << ',';
        if (sf.psnr_vs_high >= 0.0) sc << sf.psnr_vs_high;
        sc << '\n';
      }
      writeFile(out / "lod_sprite_frames.csv", sc.str());
    }
  } else if (paged) {
    const terrain::PagedTerrainStats& ps = paged->stats();
    // What drawing the whole grid would hold on the GPU: every point's position and a texel a point with mipmaps.
    const size_t whole_gpu = size_t(grid_w) * size_t(grid_h) * (sizeof(Vec3) + 4 * 4 / 3);
    j["render"] = {{"frame_ms_mean", fsum / double(fms.size())},
                   {"frame_ms_median", fms[fms.size() / 2]},
                   {"frame_ms_p99", fms[std::min(fms.size() - 1, fms.size() * 99 / 100)]},
                   {"frame_ms_max", fms.back()},
                   {"triangles_mean", double(drawn_sum) / double(rows.size())},
                   {"triangles_max", drawn_max},
                   {"prefetch_frames", o.prefetch_frames},
                   {"tiles_prefetched", st.prefetched},
                   {"prefetch_hits", st.prefetch_hits},
                   {"prefetch_waits", st.prefetch_waits},
                   {"prefetch_dropped", st.prefetch_dropped},
                   {"tile_loads_waited_for", st.loads},
                   {"patch_loads", ps.loads},
                   {"patch_evictions", ps.evictions},
                   {"patch_seconds", ps.load_seconds},
                   {"gpu_budget_bytes", paged->budget()},
                   {"gpu_peak_bytes", ps.peak_gpu_bytes},
                   {"whole_grid_gpu_bytes", whole_gpu}};
    char line[640];
    std::snprintf(line, sizeof line,
                  "\ndrawn from GPU patches: frame %.1f ms mean, %.1f median, %.1f p99, %.1f max (LOD, tile reads "
                  "waited for, patch loads and draw, to the GPU's end); %.0f triangles mean, %zu max; %zu patch "
                  "loads (%.1f s), %zu evictions; GPU peak %.0f MiB of a %.0f MiB budget (the whole grid's "
                  "positions and texture: %.0f MiB); tiles prefetched %d frames ahead: %zu (%zu of them used, %zu "
                  "waited for in flight), %zu read on demand\n",
                  fsum / double(fms.size()), fms[fms.size() / 2], double(j["render"]["frame_ms_p99"]), fms.back(),
                  double(drawn_sum) / double(rows.size()), drawn_max, ps.loads, ps.load_seconds, ps.evictions,
                  mib(ps.peak_gpu_bytes), mib(paged->budget()), mib(whole_gpu), o.prefetch_frames, st.prefetched,
                  st.prefetch_hits, st.prefetch_waits, st.loads);
    render_md = line;
  }
  writeFile(out / "tiles.json", j.dump(2) + "\n");

  std::ostringstream md;
  md << "| terrain | tiles | budget MiB | peak resident MiB (all tiles at full resolution) | loads / evictions / hits "
        "| triangles mean / max | LOD build ms mean / median (loads included) | checked frames, mismatches |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|\n";
  char line[1024];
  std::snprintf(line, sizeof line,
                "| %s | %dx%d of %d cells | %.0f | %.1f (%.1f) | %zu / %zu / %zu | %.0f / %zu | %.1f / %.1f | %zu, %zu "
                "|\n",
                source.c_str(), cache.layout().tilesX(), cache.layout().tilesY(),
                o.block * o.tile_blocks, o.budget_mb, mib(st.peak_resident_bytes), mib(full_bytes), st.loads,
                st.evictions, st.hits, mean_tri, max_tri, sum_ms / double(rows.size()), ms[ms.size() / 2],
                size_t(j["checked_frames"]), result.check_mismatches);
  md << line;
  std::snprintf(line, sizeof line,
                "\ncache %.0f MiB written in %.1f s (%s); tiles loaded %.0f MiB in %.1f s; process RSS %.0f MiB "
                "before the flythrough, at most %.0f MiB sampled during it; peak RSS of the run %.0f MiB\n",
                mib(fs::file_size(cache_path)), write_seconds,
                streamed ? "the DEM read tile by tile, never whole" : "from the whole grid", mib(st.bytes_loaded),
                st.load_seconds, mib(rss_after_drop), mib(rss_peak), mib(peakResidentSetBytes()));
  md << line;
  if (tile_sprites) {
    std::snprintf(line, sizeof line,
                  "\nsprites per tile of %d cells at %.2g px: %zu tile refreshes in %zu tile-frames in view (%.1f%%), "
                  "%.0f high-resolution triangles re-rendered per frame; whole-frame sprite: %zu keyframes in %zu "
                  "frames (%.1f%%), %.0f triangles per frame\n",
                  o.sprite_tile_cells, o.epsilon, sprite.tile_refreshes, sprite.tile_views,
                  100.0 * double(sprite.tile_refreshes) / double(std::max<size_t>(sprite.tile_views, 1)),
                  double(sprite.tile_triangles) / double(rows.size()), sprite.whole_keyframes, rows.size(),
                  100.0 * double(sprite.whole_keyframes) / double(rows.size()),
                  double(sprite.whole_triangles) / double(rows.size()));
    md << line;
  }
  md << render_md;
  result.markdown = md.str();
  writeFile(out / "tiles.md", result.markdown);
  result.seconds = total.seconds();
  return result;
}

}  // namespace farfield::eval
