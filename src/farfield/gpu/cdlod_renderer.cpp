#include "farfield/gpu/cdlod_renderer.h"

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"

namespace farfield::gpu {

CdlodRenderer::CdlodRenderer(int width, int height, std::span<const float> heights, Vec2 cell, int patch_cells,
                             const image::ColorImage& texture, Vec2 uv_scale, Vec2 uv_offset)
    : width_(width), height_(height), patch_cells_(patch_cells), cell_(cell), uv_scale_(uv_scale),
      uv_offset_(uv_offset) {
  if (width < 2 || height < 2 || heights.size() != size_t(width) * size_t(height))
    throw Error("CDLOD renderer", "a grid of " + std::to_string(width) + " x " + std::to_string(height) +
                                      " points needs as many heights, got " + std::to_string(heights.size()));
  if (patch_cells < 2 || patch_cells > 254) throw Error("CDLOD renderer", "patch size must be in 2..254");
  if (texture.empty()) throw Error("CDLOD renderer", "empty texture");
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (width > max_size || height > max_size)
    throw Error("CDLOD renderer", "a grid of " + std::to_string(width) + " x " + std::to_string(height) +
                                      " points exceeds this driver's largest texture (" + std::to_string(max_size) +
                                      "); page it in tiles");
  heights_ = Texture(width, height, TextureFormat::R32F, false);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTextureSubImage2D(heights_.handle(), 0, 0, 0, width, height, GL_RED, GL_FLOAT, heights.data());
  texture_ = Texture::fromImage(texture, true);
  texture_.setClampToEdge();
  makePatch();
}

CdlodRenderer::CdlodRenderer(int width, int height, Vec2 cell, int patch_cells, const CdlodOverview& overview,
                             CdlodPages& pages)
    : width_(width), height_(height), patch_cells_(patch_cells), cell_(cell), uv_scale_(1.0f), uv_offset_(0.0f) {
  if (width < 2 || height < 2) throw Error("CDLOD renderer", "a grid needs at least 2 x 2 points");
  if (patch_cells < 2 || patch_cells > 254) throw Error("CDLOD renderer", "patch size must be in 2..254");
  if (overview.step < 1 || (width - 1) % overview.step != 0 || (height - 1) % overview.step != 0 ||
      overview.width != (width - 1) / overview.step + 1 || overview.height != (height - 1) / overview.step + 1 ||
      overview.heights.size() != size_t(overview.width) * size_t(overview.height) || !overview.colour ||
      overview.colour->width() != overview.width || overview.colour->height() != overview.height)
    throw Error("CDLOD renderer", "the overview must hold every " + std::to_string(overview.step) +
                                      "th point of the " + std::to_string(width) + " x " + std::to_string(height) +
                                      " grid, with a texel per point");
  pages_ = &pages;
  overview_step_ = overview.step;
  heights_ = Texture(overview.width, overview.height, TextureFormat::R32F, false);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTextureSubImage2D(heights_.handle(), 0, 0, 0, overview.width, overview.height, GL_RED, GL_FLOAT,
                      overview.heights.data());
  texture_ = Texture::fromImage(*overview.colour, true);
  texture_.setClampToEdge();
  makePatch();
}

Program& CdlodRenderer::program(bool hole, bool sprite) {
  Program& p = programs_[(hole ? 1 : 0) + (sprite ? 2 : 0)];
  if (!p.handle()) {
    std::string defines;
    if (pages_) defines += "#define FF_PAGED 1\n";
    if (hole) defines += "#define FF_HOLE 1\n";
    if (sprite) defines += "#define FF_CDLOD_SPRITE 1\n";
    p = Program::fromEmbedded("cdlod.vert.glsl", "terrain.frag.glsl", defines);
  }
  return p;
}

void CdlodRenderer::makePatch() {
  const int patch_cells = patch_cells_;
  // The patch: (P + 1)^2 vertices named by gl_VertexID, each cell split along its (0,0)-(1,1) diagonal.
  std::vector<uint16_t> indices;
  const int row = patch_cells + 1;
  for (int j = 0; j < patch_cells; ++j)
    for (int i = 0; i < patch_cells; ++i) {
      const uint16_t c00 = uint16_t(i + j * row), c10 = uint16_t(c00 + 1), c01 = uint16_t(c00 + row),
                     c11 = uint16_t(c01 + 1);
      indices.insert(indices.end(), {c00, c10, c11, c00, c11, c01});
    }
  index_count_ = indices.size();
  glCreateVertexArrays(1, &vao_);
  glCreateBuffers(1, &ibo_);
  glNamedBufferStorage(ibo_, GLsizeiptr(indices.size() * sizeof(uint16_t)), indices.data(), 0);
  glVertexArrayElementBuffer(vao_, ibo_);
  glCreateBuffers(1, &nodes_);
  glCreateBuffers(kRangeSlots, ranges_);
}

CdlodRenderer::~CdlodRenderer() {
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (ibo_) glDeleteBuffers(1, &ibo_);
  if (nodes_) glDeleteBuffers(1, &nodes_);
  glDeleteBuffers(kRangeSlots, ranges_);
}

void CdlodRenderer::setLevels(std::span<const int> offsets, std::span<const IVec2> counts) {
  if (offsets.empty() || offsets.size() != counts.size() || offsets.size() > size_t(kMaxLevels))
    throw Error("CDLOD renderer", "levels: " + std::to_string(offsets.size()) + " offsets and " +
                                      std::to_string(counts.size()) + " counts (1.." + std::to_string(kMaxLevels) +
                                      " levels)");
  level_offset_.assign(offsets.begin(), offsets.end());
  level_count_.assign(counts.begin(), counts.end());
  top_ = int(offsets.size()) - 1;
}

void CdlodRenderer::setHole(Vec2 lo, Vec2 hi) {
  program(true, false);
  hole_ = true;
  hole_rect_ = Vec4(lo, hi);
}

void CdlodRenderer::setSprite(const CdlodSprite& sprite) {
  const char* where = "CDLOD renderer sprite";
  if (!sprite.colour || !sprite.depth) throw Error(where, "needs the keyframe's colour and depth textures");
  sprite.camera.validate(where);
  for (const Texture* t : {sprite.colour, sprite.depth})
    if (t->width() != sprite.camera.width || t->height() != sprite.camera.height)
      throw Error(where, "a " + std::to_string(t->width()) + " x " + std::to_string(t->height()) +
                             " texture for a keyframe camera of " + std::to_string(sprite.camera.width) + " x " +
                             std::to_string(sprite.camera.height));
  sprite_ = sprite;
  sprite_on_ = true;
}

void CdlodRenderer::setRanges(std::span<const Vec2> ranges, int slot) {
  if (ranges.empty()) throw Error("CDLOD renderer", "no node ranges");
  if (slot < 0 || slot >= kRangeSlots) throw Error("CDLOD renderer", "no range slot " + std::to_string(slot));
  range_bytes_[slot] = ranges.size() * sizeof(Vec2);
  glNamedBufferData(ranges_[slot], GLsizeiptr(range_bytes_[slot]), ranges.data(), GL_STATIC_DRAW);
}

FrameStats CdlodRenderer::draw(const Camera& camera, RenderTarget& target, std::span<const CdlodInstance> nodes,
                               int slot) {
  Stopwatch wall;
  FrameStats stats;
  if (top_ < 0) throw Error("CDLOD renderer", "draw before setLevels");
  if (slot < 0 || slot >= kRangeSlots || range_bytes_[slot] == 0)
    throw Error("CDLOD renderer", "draw with range slot " + std::to_string(slot) + ", which was never set");
  if (nodes.empty()) return stats;
  camera.validate("camera");
  const size_t bytes = nodes.size() * sizeof(CdlodInstance);
  if (bytes > node_capacity_) {
    // A new store, twice the size needed, so that a growing selection reallocates rarely.
    node_capacity_ = std::max<size_t>(bytes * 2, 4096);
    glNamedBufferData(nodes_, GLsizeiptr(node_capacity_), nullptr, GL_STREAM_DRAW);
  }
  glNamedBufferSubData(nodes_, 0, GLsizeiptr(bytes), nodes.data());

  target.bindForOpaquePass();
  Program& program = this->program(hole_, sprite_on_);
  program.use();
  program.set("u_view_proj", camera.viewProjection());
  program.set("u_eye", camera.eye);
  glUniform2fv(program.uniformLocation("u_cell"), 1, glm::value_ptr(cell_));
  glUniform2i(program.uniformLocation("u_last"), width_ - 1, height_ - 1);
  program.set("u_patch", patch_cells_);
  program.set("u_top", top_);
  glUniform1iv(program.uniformLocation("u_level_offset[0]"), GLsizei(level_offset_.size()), level_offset_.data());
  glUniform2iv(program.uniformLocation("u_level_count[0]"), GLsizei(level_count_.size()),
               glm::value_ptr(level_count_[0]));
  glUniform2fv(program.uniformLocation("u_uv_scale"), 1, glm::value_ptr(uv_scale_));
  glUniform2fv(program.uniformLocation("u_uv_offset"), 1, glm::value_ptr(uv_offset_));
  program.set("u_object_id", uint32_t(1));
  if (hole_) program.set("u_hole", hole_rect_);
  if (sprite_on_) {
    const Camera& k = sprite_.camera;
    program.set("u_sprite_view_proj", k.viewProjection());
    program.set("u_sprite_eye_beta", Vec4(k.eye, k.fovX() / float(k.width)));
    glUniform2f(program.uniformLocation("u_sprite_near_far"), k.near_plane, k.far_plane);
    program.set("u_sprite_thickness", Vec3(sprite_.thickness_m, sprite_.thickness_rel, sprite_.footprint_pixels));
    sprite_.depth->bind(4);
    sprite_.colour->bind(5);
  }
  texture_.bind(0);
  heights_.bind(1);
  if (pages_) {
    program.set("u_page_cells", pages_->pageCells());
    program.set("u_overview_step", overview_step_);
    pages_->bind(2, 3);
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, nodes_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, ranges_[slot]);
  const bool bias = bias_factor_ != 0.0f || bias_units_ != 0.0f;
  if (bias) {
    glEnable(GL_POLYGON_OFFSET_FILL);  // reversed Z: farther is smaller
    glPolygonOffset(-bias_factor_, -bias_units_);
  }
  glBindVertexArray(vao_);
  glDrawElementsInstanced(GL_TRIANGLES, GLsizei(index_count_), GL_UNSIGNED_SHORT, nullptr, GLsizei(nodes.size()));
  glBindVertexArray(0);
  if (bias) glDisable(GL_POLYGON_OFFSET_FILL);
  stats.triangles = nodes.size() * trianglesPerNode();
  stats.draw_calls = 1;
  stats.objects = 1;
  stats.wall_ms = wall.milliseconds();
  return stats;
}

void CdlodRenderer::finish() { glFinish(); }

size_t CdlodRenderer::gpuBytes() const {
  size_t bytes = heights_.byteSize() + texture_.byteSize() + index_count_ * sizeof(uint16_t) + node_capacity_;
  for (size_t b : range_bytes_) bytes += b;
  return bytes;
}

}  // namespace farfield::gpu
