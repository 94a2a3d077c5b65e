// Material: base colour and an optional texture image (multiplied together), lit or unlit.
#pragma once

#include <memory>
#include <string>

#include "farfield/core/math.h"
#include "farfield/image/image.h"

namespace farfield::scene {

struct Material {
  std::string name;
  Vec4 base_color{1.0f, 1.0f, 1.0f, 1.0f};  // linear-ish RGBA multiplier, 0..1
  std::shared_ptr<const image::ColorImage> texture;  // may be null
  std::string texture_path;  // where the texture came from, if a file (for reports and export)
  bool unlit = false;        // impostor textures already hold lit colour
  bool double_sided = false;
};

}  // namespace farfield::scene
