// 3D warping of depth images with hole filling from a second image (steed-ibr-impostors-lecture, part 2, "3D warping
// using depth information"; Mark et al.'s post-render warping).
//
// One matrix per warp: a pixel (x, y) with window depth z is the clip point (ndc_x, ndc_y, z, 1) of its camera
// (reversed Z with a [0, 1] depth range: window depth is ndc z), so target clip = VP_target * VP_source^-1 * it, in
// double precision so that a warp onto the source camera itself lands every pixel centre on its own pixel.
#include "farfield/impostor/warp.h"

#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield::impostor {
namespace {

void checkView(const DepthView& v, const char* what) {
  if (!v.color || !v.depth) throw Error(what, "missing colour or depth image");
  if (v.color->width() != v.camera.width || v.color->height() != v.camera.height ||
      v.depth->width() != v.camera.width || v.depth->height() != v.camera.height)
    throw Error(what, "image size " + std::to_string(v.color->width()) + "x" + std::to_string(v.color->height()) +
                          " is not the camera's " + std::to_string(v.camera.width) + "x" +
                          std::to_string(v.camera.height));
}

void splat(const DepthView& v, const Camera& target, uint8_t tag, bool only_holes, WarpedImage& out,
           size_t& count) {
  const glm::dmat4 m = glm::dmat4(target.viewProjection()) * glm::inverse(glm::dmat4(v.camera.viewProjection()));
  const int w = v.camera.width, h = v.camera.height, tw = target.width, th = target.height;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float z = v.depth->at(x, y);
      if (!(z > 0.0f)) continue;
      const glm::dvec4 clip = m * glm::dvec4((x + 0.5) / w * 2.0 - 1.0, 1.0 - (y + 0.5) / h * 2.0, double(z), 1.0);
      if (!(clip.w > 0.0)) continue;
      const double tx = (clip.x / clip.w * 0.5 + 0.5) * tw, ty = (0.5 - clip.y / clip.w * 0.5) * th;
      const double tz = clip.z / clip.w;
      if (!(tx >= 0.0 && ty >= 0.0 && tx < tw && ty < th) || !(tz > 0.0 && tz <= 1.0)) continue;
      const int px = int(tx), py = int(ty);
      uint8_t& src = out.source.at(px, py);
      if (only_holes && src == 1) continue;
      if (src != 0 && out.depth.at(px, py) >= float(tz)) continue;
      if (src == 0) ++count;
      src = tag;
      out.depth.at(px, py) = float(tz);
      image::Rgba8 c = v.color->at(x, y);
      c.a = 255;
      out.color.at(px, py) = c;
    }
}

WarpedImage emptyFor(const Camera& target) {
  WarpedImage out;
  out.color = image::ColorImage(target.width, target.height, image::Rgba8(0, 0, 0, 0));
  out.depth = image::DepthImage(target.width, target.height, 0.0f);
  out.source = image::Image<uint8_t>(target.width, target.height, 0);
  return out;
}

}  // namespace

WarpedImage warpDepthImage(const DepthView& view, const Camera& target) {
  checkView(view, "warp source");
  target.validate("warp target camera");
  WarpedImage out = emptyFor(target);
  splat(view, target, 1, false, out, out.from_primary);
  return out;
}

WarpedImage warpWithHoleFilling(const DepthView& primary, const DepthView& second, const Camera& target) {
  checkView(second, "warp second image");
  WarpedImage out = warpDepthImage(primary, target);
  splat(second, target, 2, true, out, out.from_second);
  return out;
}

}  // namespace farfield::impostor
