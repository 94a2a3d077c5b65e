// The window's default framebuffer (a GLFW window context, gpu/context.h): clearing it, showing a RenderTarget's
// colour in it, reading it back. For the interactive viewer, whose panels (Dear ImGui, its own OpenGL backend) are
// drawn on top of the frame between showFrame and readWindow.
#pragma once

#include "farfield/core/math.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/image.h"

namespace farfield::gpu {

// Binds the default framebuffer, sets the viewport to width x height pixels and clears its colour (and depth).
void clearWindow(int width, int height, const Vec4& color);
// Copies the target's colour into the default framebuffer, scaled (linear filtering) to fill width x height pixels,
// upright. Leaves the default framebuffer bound for drawing.
void showFrame(const RenderTarget& target, int width, int height);
// Reads width x height pixels of the default framebuffer's back buffer (what the next swap will show), row 0 at
// the top, alpha 255. Call before the swap.
image::ColorImage readWindow(int width, int height);

}  // namespace farfield::gpu
