// The terrain experiment's quality pass (every mode against the high-resolution frame, Figure 6) and Figures 9-11.
#include "farfield/eval/terrain_experiment.h"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "farfield/core/check.h"
#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/terrain_paths.h"
#include "farfield/gpu/context.h"
#include "farfield/image/metrics.h"
#include "farfield/image/png_io.h"
#include "farfield/terrain/flythrough.h"
#include "farfield/terrain/lod_sprite.h"

namespace farfield::eval::terrain_experiment {

// 2. Quality pass (untimed): every mode's frame against the high-resolution frame (and against the full-resolution
// grid's frame where it fits: which LOD is closer to the surface itself), and Figure 6's views.
void runQuality(Experiment& x) {
  const TerrainBenchOptions& o = x.options;
  const BenchResult& bench = x.result.bench;
  const terrain::TerrainData& data = x.data();
  const bool full = size_t(data.hf.width - 1) * size_t(data.hf.height - 1) * 2 <= o.full_max_triangles;
  say(o, "quality: frames against high resolution (every %zu)\n", o.quality_stride);
  gpu::TerrainRenderer& renderer = x.run->gpuRenderer();
  gpu::RenderTarget target(o.width, o.height);
  std::vector<std::pair<std::string, std::unique_ptr<terrain::LodSpriteRenderer>>> sprites;
  for (const std::string& name : o.modes) {
    SpriteVariant variant;
    bool gpu_high = false;
    if (!spriteVariantOf(name, variant, &gpu_high)) continue;
    sprites.emplace_back(name, std::make_unique<terrain::LodSpriteRenderer>(
                                   *data.lod, renderer, o.width, o.height,
                                   spriteOptions(*x.run, variant, o.epsilon, gpu_high ? &x.run->gpuLod() : nullptr)));
  }
  std::vector<std::pair<std::string, std::unique_ptr<terrain::TileSpriteRenderer>>> tiles;
  for (const std::string& name : o.modes) {
    if (isTileSpriteMode(name))
      tiles.emplace_back(name, std::make_unique<terrain::TileSpriteRenderer>(*data.lod, renderer, o.width, o.height,
                                                                             tileSpriteOptions(*x.run, name)));
  }
  // Figure 6 and 7's views: over the plain (40% of the path) and over the mountains (70%).
  const std::set<size_t> views{bench.frame_indices[bench.frame_indices.size() * 2 / 5],
                               bench.frame_indices[bench.frame_indices.size() * 7 / 10]};
  std::ostringstream views_csv;
  views_csv << "view,path_frame,high_triangles,low_triangles,lod_sprite_triangles,psnr_low_vs_high_db,"
               "psnr_lod_sprite_vs_high_db,mae_low,mae_lod_sprite\n";
  int view_number = 0;
  terrain::LodMesh mesh;
  Progress progress("quality", bench.frame_indices.size());
  for (size_t k = 0; k < bench.frame_indices.size(); ++k) {
    const size_t pf = bench.frame_indices[k];
    const Camera camera = x.cameraAt(x.path, pf);
    const bool measure = k % o.quality_stride == 0 || views.count(pf);
    TerrainQualityRow row;
    row.path_frame = pf;
    image::ColorImage high_image, low_image, full_image;
    uint64_t high_tris = 0, low_tris = 0;
    // A mode's frame against high (and full): the one place the rows are filled.
    auto compare = [&](const std::string& name, const image::ColorImage& img) {
      row.psnr[name] = std::min(image::psnr(high_image, img), kPsnrCapDb);
      if (full) row.psnr_full[name] = std::min(image::psnr(full_image, img), kPsnrCapDb);
    };
    if (measure && full) {
      target.clear(x.run->sky);
      terrain::renderLodFrame(*data.lod, renderer, camera, {1e-6f, true, false}, target, mesh);
      full_image = target.readColor();
    }
    if (measure) {
      target.clear(x.run->sky);
      high_tris = terrain::renderLodFrame(*data.lod, renderer, camera, {o.high_error, true, false}, target, mesh)
                      .triangles;
      high_image = target.readColor();
      target.clear(x.run->sky);
      low_tris = terrain::renderLodFrame(*data.lod, renderer, camera, {o.low_error, true, false}, target, mesh)
                     .triangles;
      low_image = target.readColor();
      compare("low", low_image);
      if (full) row.psnr_full["high"] = std::min(image::psnr(full_image, high_image), kPsnrCapDb);
    }
    for (auto& [name, s] : sprites) {
      target.clear(x.run->sky);
      terrain::LodSpriteFrameInfo info;
      s->render(camera, target, &info);
      if (!measure) continue;
      const image::ColorImage img = target.readColor();
      compare(name, img);
      if (name == "lod-sprite" && views.count(pf)) {
        ++view_number;
        const std::string tag = "view" + std::to_string(view_number);
        const fs::path dir = x.figures / "fig06";
        image::writePng((dir / (tag + "_a_low.png")).string(), low_image);
        image::writePng((dir / (tag + "_b_high.png")).string(), high_image);
        image::writePng((dir / (tag + "_c_lod_sprite.png")).string(), img);
        image::writePng((dir / (tag + "_d_diff_low_high.png")).string(), absDifference(low_image, high_image));
        image::writePng((dir / (tag + "_e_diff_high_lod_sprite.png")).string(), absDifference(high_image, img));
        views_csv << view_number << "," << pf << "," << high_tris << "," << low_tris << ","
                  << info.low_triangles + info.keyframe_triangles << "," << num(row.psnr["low"], 3) << ","
                  << num(row.psnr[name], 3) << "," << num(image::meanAbsoluteError(high_image, low_image), 3) << ","
                  << num(image::meanAbsoluteError(high_image, img), 3) << "\n";
      }
    }
    for (auto& [name, t] : tiles) {
      target.clear(x.run->sky);
      t->render(camera, target);
      if (!measure) continue;
      const image::ColorImage img = target.readColor();
      compare(name, img);
      if (views.count(pf)) {  // Figure 6's views for the tile modes too, next to lod-sprite's
        const std::string tag = "view" + std::to_string(1 + std::distance(views.begin(), views.find(pf)));
        const fs::path dir = x.figures / "fig06";
        image::writePng((dir / (tag + "_f_" + name + ".png")).string(), img);
        image::writePng((dir / (tag + "_g_diff_high_" + name + ".png")).string(), absDifference(high_image, img));
      }
    }
    for (const std::string& name : o.modes) {  // the CDLOD terrain on the GPU at each threshold
      if (!measure || (name != "high-gpu" && name != "low-gpu")) continue;
      target.clear(x.run->sky);
      x.run->gpuLod().draw(camera, name == "high-gpu" ? o.high_error : o.low_error, target);
      const image::ColorImage img = target.readColor();
      compare(name, img);
      if (views.count(pf)) {
        const std::string tag = "view" + std::to_string(1 + std::distance(views.begin(), views.find(pf)));
        const fs::path dir = x.figures / "fig06";
        image::writePng((dir / (tag + "_f_" + name + ".png")).string(), img);
        image::writePng((dir / (tag + "_g_diff_high_" + name + ".png")).string(), absDifference(high_image, img));
      }
    }
    if (measure) x.result.quality.push_back(std::move(row));
    progress.advance();
  }
  progress.finish();
  writeText(x.figures / "fig06_views.csv", views_csv.str());
  for (const TerrainQualityRow& row : x.result.quality) {
    for (const auto& [name, v] : row.psnr) x.result.psnr_mean[name] += v / double(x.result.quality.size());
    for (const auto& [name, v] : row.psnr_full) x.result.psnr_full_mean[name] += v / double(x.result.quality.size());
  }

  std::ostringstream q;
  q << "path_frame";
  auto namesOf = [&](const std::map<std::string, double> TerrainQualityRow::*column) {
    std::vector<std::string> names;
    if (!x.result.quality.empty())
      for (const auto& [name, v] : x.result.quality.front().*column) names.push_back(name);
    return names;
  };
  const std::vector<std::string> qnames = namesOf(&TerrainQualityRow::psnr);
  const std::vector<std::string> fnames = namesOf(&TerrainQualityRow::psnr_full);
  for (const std::string& n : qnames) q << ",psnr_" << n << "_vs_high_db";
  for (const std::string& n : fnames) q << ",psnr_" << n << "_vs_full_db";
  q << "\n";
  for (const TerrainQualityRow& row : x.result.quality) {
    q << row.path_frame;
    for (const std::string& n : qnames) q << "," << num(row.psnr.at(n), 3);
    for (const std::string& n : fnames) q << "," << num(row.psnr_full.at(n), 3);
    q << "\n";
  }
  writeText(x.figures / "quality.csv", q.str());
}

// 3. Figures 9-11: per-frame triangles, error, time (from the harness's records and the sprite mode's log).
void writePerFrameFigures(const Experiment& x) {
  const BenchResult& bench = x.result.bench;
  const ModeResult& high = *bench.mode("high");
  const ModeResult& low = *bench.mode("low");
  const ModeResult& sprite = *bench.mode("lod-sprite");
  const std::vector<SpriteLog>& log = x.result.sprite_log;
  std::ostringstream f9, f10, f11;
  f9 << "frame,path_frame,high,low,lod_sprite,keyframe\n";
  f10 << "frame,path_frame,error_px,trigger_error_px,keyframe,source,path,keyframe_due,predicted_high_ms,"
         "predicted_sprite_ms,predicted_keyframe_ms,expected_lifetime,switched\n";
  f11 << "frame,path_frame";
  for (const ModeResult& m : bench.modes) f11 << "," << m.name << "_ms";
  f11 << ",lod_sprite_keyframe,lod_sprite_path\n";
  for (size_t k = 0; k < bench.frame_indices.size(); ++k) {
    const bool key = log[k].info.source == terrain::SpriteSource::Fresh;
    f9 << k << "," << bench.frame_indices[k] << "," << high.frames[k].triangles << "," << low.frames[k].triangles
       << "," << sprite.frames[k].triangles << "," << key << "\n";
    f10 << k << "," << bench.frame_indices[k] << "," << num(log[k].info.error_px) << ","
        << num(log[k].info.trigger_error_px) << "," << key << "," << terrain::spriteSourceName(log[k].info.source)
        << "," << terrain::terrainPathName(log[k].info.path) << "," << log[k].info.keyframe_due << ","
        << num(log[k].info.predicted_high_ms, 3) << "," << num(log[k].info.predicted_sprite_ms, 3) << ","
        << num(log[k].info.predicted_keyframe_ms, 3) << "," << num(log[k].info.expected_lifetime, 1) << ","
        << log[k].info.switched << "\n";
    f11 << k << "," << bench.frame_indices[k];
    for (const ModeResult& m : bench.modes) f11 << "," << num(m.frames[k].wall_ms, 3);
    f11 << "," << key << "," << terrain::terrainPathName(log[k].info.path) << "\n";
  }
  writeText(x.figures / "fig09_triangles.csv", f9.str());
  writeText(x.figures / "fig10_error.csv", f10.str());
  writeText(x.figures / "fig11_time.csv", f11.str());
}

}  // namespace farfield::eval::terrain_experiment
