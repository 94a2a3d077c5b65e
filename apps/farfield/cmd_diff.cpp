// farfield diff A.png B.png [--heatmap d.png] [--threshold 8] [--json]
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/error.h"
#include "farfield/image/metrics.h"
#include "farfield/image/png_io.h"

namespace farfield::app {
namespace {

struct DiffArgs {
  std::string a, b, heatmap;
  int threshold = 8;
  bool json = false;
};

void runDiff(const DiffArgs& args) {
  if (args.threshold < 0 || args.threshold > 255) throw Error("--threshold", "expected 0..255");
  const image::ColorImage a = image::readPng(args.a);
  const image::ColorImage b = image::readPng(args.b);
  if (a.width() != b.width() || a.height() != b.height())
    throw Error(args.b, "size " + std::to_string(b.width()) + "x" + std::to_string(b.height()) + " differs from " +
                            args.a + " (" + std::to_string(a.width()) + "x" + std::to_string(a.height()) + ")");
  const image::ImageMetrics m = image::compareImages(a, b, args.threshold);
  if (!args.heatmap.empty()) {
    ensureParentDirectory(args.heatmap);
    image::writePng(args.heatmap, image::diffHeatmap(a, b));
  }
  if (args.json) {
    nlohmann::json j;
    j["a"] = args.a;
    j["b"] = args.b;
    j["psnr_db"] = std::isfinite(m.psnr_db) ? nlohmann::json(m.psnr_db) : nlohmann::json(nullptr);
    j["identical"] = !std::isfinite(m.psnr_db);
    j["mae"] = m.mae;
    j["ssim"] = m.ssim;
    j["threshold"] = args.threshold;
    j["share_over_threshold"] = m.bad_pixel_share;
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    if (std::isfinite(m.psnr_db))
      std::printf("psnr_db:              %.3f\n", m.psnr_db);
    else
      std::printf("psnr_db:              inf (identical)\n");
    std::printf("mae:                  %.4f\n", m.mae);
    std::printf("ssim:                 %.5f\n", m.ssim);
    std::printf("share_over_%d_of_255: %.6f\n", args.threshold, m.bad_pixel_share);
  }
}

const RegisterCommand reg("diff", [](CLI::App& app) {
  auto args = std::make_shared<DiffArgs>();
  auto* cmd = app.add_subcommand("diff", "Compare two images: PSNR, MAE, SSIM, share of pixels over a threshold.");
  cmd->add_option("a", args->a, "Reference PNG")->required();
  cmd->add_option("b", args->b, "Test PNG")->required();
  cmd->add_option("--heatmap", args->heatmap, "Write a difference heat map PNG");
  cmd->add_option("--threshold", args->threshold, "Per-channel difference (0..255) that makes a pixel bad")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "Print JSON");
  cmd->callback([args] { runDiff(*args); });
});

}  // namespace
}  // namespace farfield::app
