#include "farfield/view/panels.h"

#include <imgui.h>

#include <cinttypes>
#include <cmath>
#include <cstdio>

namespace farfield::view {
namespace {

ImVec4 imColor(const Vec4& c) { return ImVec4(c.r, c.g, c.b, c.a); }

void sectionTitle(const char* title) {
  ImGui::Separator();
  ImGui::TextDisabled("%s", title);
}

void drawPromises(const PanelState& s) {
  const PromiseCounts& p = s.history->promises();
  sectionTitle("Promises");
  if (s.t_max_ms > 0.0)
    ImGui::Text("t_max %.1f ms: broken in %zu of %zu frames", s.t_max_ms, p.over_t_max, p.frames);
  if (s.bound_px > 0.0) {
    ImGui::Text("bound %.2f px: broken in %zu frames", s.bound_px, p.boundBroken());
    ImGui::Text("  parallax over it: %zu of %zu checked", p.over_bound, p.checked);
    ImGui::Text("  layers unchecked: %zu frames", p.unchecked_frames);
  } else {
    ImGui::TextDisabled("bound: none in this mode");
  }
}

void drawWalkthrough(const PanelState& s) {
  const runtime::FramePlan* plan = s.frame.plan;
  if (!plan) return;
  const runtime::FrameReport& r = plan->report;
  sectionTitle("Walkthrough");
  if (r.cell != urban::kNone)
    ImGui::Text("cell %u%s", r.cell, r.baked ? "" : " (not baked: culled geometry)");
  else
    ImGui::Text("cell: none%s", r.cpv != urban::kNone ? "" : " (outside the streets)");
  if (r.cpv != urban::kNone) ImGui::Text("CPV %u, placed time bound %.1f ms", r.cpv, r.cpv_t_after_ms);
  // A GPU-driven plan lists whole objects, which the GPU then culls: its count is what it may draw, not what it drew
  // (the frame's line above).
  const bool listed = plan->geometry_items == 0 && !plan->geometry_objects.empty();
  ImGui::Text("triangles: %" PRIu64 " geometry%s, %" PRIu64 " impostor", r.geometry_triangles,
              listed ? " listed for the GPU" : "", r.impostor_triangles);
  // Every kind the mode can draw, zeros included, so that the panel keeps its size from frame to frame.
  const bool placed = s.modes[size_t(s.mode_index)] == "placed";
  for (size_t k = placed ? 4 : 0; k < (placed ? kDecisionKinds : 4); ++k) {
    ImGui::ColorButton(decisionName(k), imColor(decisionTint(k)), ImGuiColorEditFlags_NoTooltip, ImVec2(10, 10));
    ImGui::SameLine();
    ImGui::Text("%-20s %zu", decisionName(k), s.frame.decisions[k]);
  }
  const double mb = double(r.resident_bytes) / 1048576.0, budget = double(s.gpu_budget_bytes) / 1048576.0;
  char label[64];
  std::snprintf(label, sizeof(label), "%.1f / %.0f MB", mb, budget);
  ImGui::Text("GPU resident");
  ImGui::SameLine();
  ImGui::ProgressBar(budget > 0.0 ? float(mb / budget) : 0.0f, ImVec2(-1, 0), label);
  if (r.over_gpu_budget) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "over the GPU budget");
}

}  // namespace

PanelActions drawMainPanel(PanelState& s) {
  PanelActions actions;
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("Farfield", nullptr, ImGuiWindowFlags_AlwaysAutoResize);

  if (ImGui::BeginCombo("mode", s.modes.empty() ? "" : s.modes[size_t(s.mode_index)].c_str())) {
    for (size_t i = 0; i < s.modes.size(); ++i) {
      char label[64];
      std::snprintf(label, sizeof(label), "%zu  %s", i + 1, s.modes[i].c_str());
      if (ImGui::Selectable(label, int(i) == s.mode_index) && int(i) != s.mode_index) actions.select_mode = s.modes[i];
    }
    ImGui::EndCombo();
  }
  int nav = s.navigation == Navigation::Walk ? 1 : 0;
  if (ImGui::RadioButton("fly", &nav, 0)) actions.navigation_changed = s.navigation != Navigation::Fly;
  ImGui::SameLine();
  if (ImGui::RadioButton("walk (1.7 m)", &nav, 1)) actions.navigation_changed = s.navigation != Navigation::Walk;
  s.navigation = nav ? Navigation::Walk : Navigation::Fly;
  if (s.camera) {
    ImGui::SliderFloat("speed m/s", &s.camera->speed, 0.5f, 500.0f, "%.1f", ImGuiSliderFlags_Logarithmic);
    ImGui::SliderFloat("fov deg", &s.camera->fov_deg, 15.0f, 120.0f, "%.0f");
  }
  ImGui::Checkbox("tint impostors", &s.tint);
  ImGui::SameLine();
  ImGui::Checkbox("map", &s.show_map);
  ImGui::Checkbox("check every frame", &s.check_every_frame);
  ImGui::SameLine();
  if (ImGui::SmallButton("check (R)")) actions.check_now = true;

  sectionTitle("Frame");
  const FrameHistory& h = *s.history;
  const float top = std::max(1.0f, h.maxMs() * 1.1f);
  char overlay[64];
  std::snprintf(overlay, sizeof(overlay), "CPU %.2f ms", s.frame.cpu_ms);
  ImGui::PlotLines("##cpu", h.cpuMs().data(), int(h.cpuMs().size()), int(h.offset()), overlay, 0.0f, top,
                   ImVec2(320, 48));
  std::snprintf(overlay, sizeof(overlay), "GPU %.2f ms", s.frame.gpu_ms);
  ImGui::PlotLines("##gpu", h.gpuMs().data(), int(h.gpuMs().size()), int(h.offset()), overlay, 0.0f, top,
                   ImVec2(320, 48));
  ImGui::Text("triangles %" PRIu64 ", draw calls %u", s.frame.triangles, s.frame.draw_calls);
  if (s.crowd) ImGui::Text("crowd: %zu skinned, %zu impostors", s.crowd_geometry, s.crowd_impostors);
  if (const auto& g = s.frame.governance) {
    ImGui::Text("governor: level %zu, predicted %.2f ms (%.2f corrected)", g->level, g->predicted_ms,
                g->corrected_ms);
    if (g->bound_scale > 1.0) ImGui::Text("  relaxed: bound %.2f px kept (%.2fx)", s.frame.kept_bound_px,
                                          g->bound_scale);
  }
  drawWalkthrough(s);
  drawPromises(s);
  float t_max = float(s.t_max_ms);
  if (ImGui::InputFloat("t_max ms", &t_max, 1.0f, 10.0f, "%.1f") && t_max >= 0.0f) s.t_max_ms = t_max;

  if (!s.path_status.empty() || !s.record_status.empty()) sectionTitle("Path");
  if (!s.path_status.empty()) ImGui::TextUnformatted(s.path_status.c_str());
  if (!s.record_status.empty()) ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "%s", s.record_status.c_str());
  if (!s.message.empty()) ImGui::TextWrapped("%s", s.message.c_str());
  if (ImGui::CollapsingHeader("Keys")) {
    ImGui::TextUnformatted(
        "W/S/A/D move, Q/E down/up (fly), shift faster\n"
        "drag (left or right button) to look\n"
        "Tab fly/walk   1-9 mode   T tint   M map\n"
        "R reference check   P pause the path\n"
        "K start/stop recording   F12 screenshot\n"
        "Esc quit");
  }
  ImGui::End();
  return actions;
}

void drawReferencePanel(const ReferenceCheck& c, unsigned heatmap_texture, unsigned parallax_texture) {
  const ImGuiViewport* viewport = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(viewport->Size.x - 8, viewport->Size.y - 8), ImGuiCond_FirstUseEver, ImVec2(1, 1));
  ImGui::Begin("Reference check", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::Text("frame %zu against full geometry", c.frame);
  ImGui::Text("PSNR %.1f dB, SSIM %.3f, %.2f %% pixels off > 8/255", c.psnr_db, c.ssim, 100.0 * c.bad_pixel_share);
  if (std::isnan(c.parallax_px))
    ImGui::TextUnformatted("parallax: n/a (impostors without object ids)");
  else if (c.bound_px > 0.0)
    ImGui::TextColored(c.over_bound ? ImVec4(1, 0.4f, 0.3f, 1) : ImVec4(0.5f, 1, 0.5f, 1),
                       "parallax p99 %.2f px, bound %.2f px: %s", c.parallax_px, c.bound_px,
                       c.over_bound ? "broken" : "kept");
  else
    ImGui::Text("parallax p99 %.2f px", c.parallax_px);
  const float w = 260.0f, h = c.heatmap.width() > 0 ? w * float(c.heatmap.height()) / float(c.heatmap.width()) : w;
  ImGui::BeginGroup();
  ImGui::TextUnformatted("difference");
  ImGui::Image(ImTextureID(intptr_t(heatmap_texture)), ImVec2(w, h));
  ImGui::EndGroup();
  ImGui::SameLine();
  ImGui::BeginGroup();
  ImGui::TextUnformatted("parallax (1-32 px)");
  ImGui::Image(ImTextureID(intptr_t(parallax_texture)), ImVec2(w, h));
  ImGui::EndGroup();
  ImGui::End();
}

bool drawErrorModal(const std::string& message, bool fatal) {
  const char* title = fatal ? "Error###farfield-error" : "Cannot do that###farfield-error";
  if (!ImGui::IsPopupOpen(title)) ImGui::OpenPopup(title);
  bool dismissed = false;
  const ImGuiViewport* viewport = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(viewport->Size.x * 0.5f, viewport->Size.y * 0.5f), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(std::min(640.0f, viewport->Size.x - 40.0f), 0));
  if (ImGui::BeginPopupModal(title, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::TextWrapped("error: %s", message.c_str());
    ImGui::Separator();
    if (ImGui::Button(fatal ? "Quit" : "OK", ImVec2(120, 0)) || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape), false)) {
      dismissed = true;
      ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
  }
  return dismissed;
}

}  // namespace farfield::view
