#include "farfield/eval/cull_check.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/eval/bench.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/image/metrics.h"

namespace farfield::eval {

CullCheckResult runCullCheck(gpu::Context& context, const scene::Scene& scene, const gen::CameraPath& path,
                             const CullCheckOptions& options) {
  if (path.frames.empty()) throw Error("camera path", "has no frames");
  if (options.stride < 1) throw Error("--stride", "must be at least 1");
  std::vector<size_t> indices;
  for (size_t i = 0; i < path.frames.size(); i += options.stride) {
    if (options.frames != 0 && indices.size() >= options.frames) break;
    indices.push_back(i);
  }
  std::vector<Camera> cameras;
  for (size_t i : indices)
    cameras.push_back(pathCamera(path, i, options.width, options.height, options.near_plane, options.far_plane));

  context.makeCurrent();
  CullCheckResult result;
  result.renderer = context.description();
  result.width = options.width;
  result.height = options.height;
  const gpu::GpuScene gpu_scene(scene);
  const gpu::SceneArena arena(scene);
  gpu::GpuCuller culler(arena, options.cull);
  gpu::Renderer renderer;
  gpu::RenderTarget reference_target(options.width, options.height), target(options.width, options.height);
  std::vector<gpu::DrawItem> items;
  Progress progress("cull check", cameras.size());
  result.psnr_db_min = kPsnrCapDb;
  double tie_sum = 0.0, colour_tie_sum = 0.0;
  for (size_t k = 0; k < cameras.size(); ++k) {
    const Camera& camera = cameras[k];
    CullCheckFrame frame;
    frame.path_frame = indices[k];
    items.clear();
    gpu_scene.appendDrawItems({}, items, camera);
    renderer.setLastWinsTies(true);
    renderer.render(camera, items, reference_target);
    const image::IdImage last_wins = reference_target.readIds();
    const image::ColorImage last_wins_color = reference_target.readColor();
    renderer.setLastWinsTies(false);
    frame.reference_triangles = renderer.render(camera, items, reference_target).triangles;
    const image::ColorImage want_color = reference_target.readColor();
    const image::IdImage want_ids = reference_target.readIds();

    target.bind();
    target.clear(renderer.light().sky_color);
    culler.draw(camera, target, gpu::RenderMode::Shaded, renderer.light());
    const image::ColorImage color = target.readColor();
    const image::IdImage ids = target.readIds();
    for (size_t p = 0; p < ids.pixelCount(); ++p) {
      if (want_ids.pixels()[p] != last_wins.pixels()[p]) {
        ++frame.ties;
        continue;
      }
      // Coplanar faces of one object (a window on its wall): the object is the same, the colour depends on order.
      frame.colour_ties += !(want_color.pixels()[p] == last_wins_color.pixels()[p]);
      frame.differing += ids.pixels()[p] != want_ids.pixels()[p];
    }
    frame.psnr_db = std::min(image::psnr(want_color, color), kPsnrCapDb);
    result.frames_differing += frame.differing > 0;
    result.differing_max = std::max(result.differing_max, frame.differing);
    result.psnr_db_min = std::min(result.psnr_db_min, frame.psnr_db);
    tie_sum += double(frame.ties) / double(ids.pixelCount());
    colour_tie_sum += double(frame.colour_ties) / double(ids.pixelCount());
    result.frames.push_back(frame);
    progress.advance();
  }
  progress.finish();
  result.tie_share_mean = tie_sum / double(result.frames.size());
  result.colour_tie_share_mean = colour_tie_sum / double(result.frames.size());
  result.passed = result.frames_differing == 0 && result.psnr_db_min >= options.min_psnr_db;
  return result;
}

void writeCullCheck(const CullCheckResult& r, const std::string& scene_label, const std::string& path_label,
                    const std::string& out_dir) {
  std::filesystem::create_directories(out_dir);
  nlohmann::ordered_json j;
  j["scene"] = scene_label;
  j["path"] = path_label;
  j["renderer"] = r.renderer;
  j["size"] = {r.width, r.height};
  j["frames"] = r.frames.size();
  j["frames_differing"] = r.frames_differing;
  j["differing_pixels_max"] = r.differing_max;
  j["psnr_db_min"] = r.psnr_db_min;
  j["tie_share_mean"] = r.tie_share_mean;
  j["colour_tie_share_mean"] = r.colour_tie_share_mean;
  j["passed"] = r.passed;
  nlohmann::ordered_json frames = nlohmann::ordered_json::array();
  for (const CullCheckFrame& f : r.frames)
    frames.push_back({{"path_frame", f.path_frame}, {"differing", f.differing}, {"ties", f.ties},
                      {"colour_ties", f.colour_ties}, {"psnr_db", f.psnr_db},
                      {"reference_triangles", f.reference_triangles}});
  j["per_frame"] = frames;
  const std::filesystem::path dir(out_dir);
  std::ofstream((dir / "cullcheck.json").string()) << j.dump(1) << "\n";
  std::ostringstream md;
  md << "# GPU-culled frames against frustum-culled frames\n\n"
     << "- scene: `" << scene_label << "`, path: `" << path_label << "`, " << r.frames.size() << " frames at "
     << r.width << "x" << r.height << "\n- renderer: " << r.renderer << "\n\n"
     << "| frames | frames with a differing object pixel | most differing pixels | PSNR min dB | tie pixels (mean) | "
        "colour ties within an object (mean) | result |\n|---:|---:|---:|---:|---:|---:|---|\n"
     << "| " << r.frames.size() << " | " << r.frames_differing << " | " << r.differing_max << " | " << r.psnr_db_min
     << " | " << 100.0 * r.tie_share_mean << "% | " << 100.0 * r.colour_tie_share_mean << "% | "
     << (r.passed ? "passed" : "FAILED") << " |\n";
  std::ofstream((dir / "cullcheck.md").string()) << md.str();
}

}  // namespace farfield::eval
