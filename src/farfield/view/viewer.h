// The interactive viewer (`farfield view`): a GLFW window with Dear ImGui panels over the runtime, Farfield's one
// renderer and eval's reference measures. Fly or walk through a scene in any mode its impostor database offers
// (mode_renderer.h), switching modes while running; see what each frame drew and whether it kept the two promises;
// check a frame against full geometry; record and replay camera paths; take screenshots.
//
// Scriptable: with `replay` the path's frames are shown one per displayed frame (no input needed), the frames listed
// in screenshot_at are written as DIR/frame_N.png (the 3D frame: the render target) and DIR/window_N.png (the
// window, panels included), and with exit_at_end the viewer closes after the path's last frame. `record` writes the
// cameras shown, as a camera path, when the viewer closes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "farfield/scene/scene.h"
#include "farfield/view/camera_controller.h"
#include "farfield/view/viewer_crowd.h"

namespace farfield::view {

struct ViewerOptions {
  std::string scene_file;          // for the window title and the street graph next to it (CITY.streets.json)
  std::string impostors;           // impostor database directory ("" = none: full and culled only)
  std::string streets;             // street graph for the map ("" = the database's, else the one next to the scene)
  std::string mode;                // starting mode ("" = the database's best, else full)
  std::string path;                // a camera path played in real time, looping (P pauses)
  std::string replay;              // a camera path shown one frame per displayed frame
  std::vector<size_t> screenshot_at;  // replay frames to write (or shown frames without a replay)
  std::string out_dir = ".";       // where screenshots go
  bool exit_at_end = false;        // close after the replay's last frame (or the last screenshot); errors close at once
  std::string record;              // camera path file written at exit with every camera shown ("" = none; K records
                                   // to out_dir/view_path.json)
  int width = 1280;                // window and frame size, pixels
  int height = 720;
  double t_max_ms = 1000.0 / 30.0; // the frame budget the panel counts against (0 = none)
  double error_px = 0.0;           // the walkthrough's bound; 0 = the database's
  bool tint = false;               // impostors tinted by kind
  bool show_map = true;
  bool check_every_frame = false;  // reference check of every frame (slow)
  Navigation navigation = Navigation::Fly;
  std::string terrain;             // a terrain under the city in full and culled (DEM file or fractal:...; "" = none)
  float terrain_scale = 1.0f;      // the vertical scale the city was made with (gen city --terrain-scale)
  // How the terrain is drawn (eval/city_on_terrain_mode.h): lod-sprite-gpu (LOD-sprite over CDLOD keyframes, no
  // per-frame CPU mesh; the default), high-gpu (CDLOD at 1 px), lod-sprite or high (the quadtree LOD on the CPU).
  std::string terrain_technique = "lod-sprite-gpu";
  // A crowd on the street graph's sidewalks, drawn over every mode's frame (viewer_crowd.h; crowd.agents 0: none).
  // Its time follows the display (a replay: 30 frames a second of the path).
  ViewerCrowdOptions crowd;
};

// Checks the options that need no window (sizes, files to read); throws farfield::Error naming the option.
void checkViewerOptions(const ViewerOptions& options);

// Opens the window and runs until it is closed (Esc, the window's close button) or, with exit_at_end, the replay
// ends. Throws farfield::Error for bad input: before the window opens (options, paths), or after (a bad or damaged
// database, a frame that cannot be drawn), in which case the error is shown in a modal first unless exit_at_end.
void runViewer(const scene::Scene& scene, const ViewerOptions& options);

}  // namespace farfield::view
