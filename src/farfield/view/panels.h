// The viewer's Dear ImGui panels: the main panel (mode, camera, frame-time graph, what was drawn, the database's
// residency, the two promises, path and recording state, keys), the reference check's panel (heat map and parallax
// map beside their numbers) and the error modal. Drawing only: the viewer owns the state and acts on what the user
// changed (PanelActions).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "farfield/view/camera_controller.h"
#include "farfield/view/frame_history.h"
#include "farfield/view/impostor_kinds.h"
#include "farfield/view/mode_renderer.h"
#include "farfield/view/reference_check.h"

namespace farfield::view {

// What the panels show and let the user change (the viewer keeps it between frames).
struct PanelState {
  std::vector<std::string> modes;
  int mode_index = 0;
  Navigation navigation = Navigation::Fly;
  ControllerSettings* camera = nullptr;  // speed, field of view
  bool tint = false;
  bool show_map = true;
  bool check_every_frame = false;
  double t_max_ms = 1000.0 / 30.0;
  double bound_px = 0.0;                // 0 = none (full, culled)
  uint64_t gpu_budget_bytes = 0;
  // This frame.
  ViewFrame frame;
  bool crowd = false;  // a crowd is drawn over the frame (its time and triangles are in `frame`)
  size_t crowd_geometry = 0, crowd_impostors = 0;
  const FrameHistory* history = nullptr;
  std::string path_status;              // "" = no path
  std::string record_status;            // "" = not recording
  std::string message;                  // last action (screenshot written, path saved)
};

struct PanelActions {
  std::optional<std::string> select_mode;
  bool navigation_changed = false;
  bool check_now = false;
};

PanelActions drawMainPanel(PanelState& state);

// The reference check's panel; textures are the GL names of its heat map and parallax map (gpu::Texture::handle()).
void drawReferencePanel(const ReferenceCheck& check, unsigned heatmap_texture, unsigned parallax_texture);

// A modal with the message; returns true when the user dismissed it (button or Escape). fatal: "Quit" instead of "OK".
bool drawErrorModal(const std::string& message, bool fatal);

}  // namespace farfield::view
