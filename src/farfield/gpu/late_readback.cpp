#include "farfield/gpu/late_readback.h"

#include <epoxy/gl.h>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::gpu {

LateReadback::LateReadback(size_t bytes, size_t slots) : bytes_(bytes), slots_(slots) {
  if (bytes == 0 || slots == 0) throw Error("late readback", "needs at least one byte and one slot");
  const GLbitfield flags = GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
  for (Slot& s : slots_) {
    glCreateBuffers(1, &s.buffer);
    glNamedBufferStorage(s.buffer, GLsizeiptr(bytes), nullptr, flags);
    s.mapped = static_cast<const uint8_t*>(glMapNamedBufferRange(s.buffer, 0, GLsizeiptr(bytes), flags));
    FF_CHECK_MSG(s.mapped != nullptr, "mapping a readback buffer failed");
  }
}

LateReadback::~LateReadback() {
  for (Slot& s : slots_) {
    if (s.fence) glDeleteSync(static_cast<GLsync>(s.fence));
    if (s.buffer) {
      glUnmapNamedBuffer(s.buffer);
      glDeleteBuffers(1, &s.buffer);
    }
  }
}

bool LateReadback::capture(uint32_t buffer, size_t offset, uint64_t frame) {
  Slot& s = slots_[next_];
  if (s.fence) {
    ++skipped_;
    return false;
  }
  glCopyNamedBufferSubData(buffer, s.buffer, GLintptr(offset), 0, GLsizeiptr(bytes_));
  s.fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  s.frame = frame;
  next_ = (next_ + 1) % slots_.size();
  return true;
}

size_t LateReadback::finished(const std::function<void(uint64_t, std::span<const uint8_t>)>& use) {
  size_t n = 0;
  // Captures fill the ring in order: the oldest in flight is the first busy slot from next_.
  for (size_t k = 0; k < slots_.size(); ++k) {
    Slot& s = slots_[(next_ + k) % slots_.size()];
    if (!s.fence) continue;
    GLint status = GL_UNSIGNALED;
    glGetSynciv(static_cast<GLsync>(s.fence), GL_SYNC_STATUS, 1, nullptr, &status);
    if (status != GL_SIGNALED) break;
    glDeleteSync(static_cast<GLsync>(s.fence));
    s.fence = nullptr;
    use(s.frame, std::span<const uint8_t>(s.mapped, bytes_));
    ++n;
  }
  return n;
}

LateTimer::LateTimer(size_t slots, GpuTimer::Source source) : slots_(slots) {
  if (slots == 0) throw Error("late timer", "needs at least one slot");
  for (Slot& s : slots_) s.timer = std::make_unique<GpuTimer>(source);
}

LateTimer::~LateTimer() = default;

void LateTimer::begin(uint64_t frame) {
  Slot& s = slots_[next_];
  if (s.busy) {
    ++skipped_;
    open_ = nullptr;
    return;
  }
  s.frame = frame;
  s.timer->begin();
  open_ = &s;
}

void LateTimer::end() {
  if (!open_) return;
  open_->timer->end();
  open_->busy = true;
  open_ = nullptr;
  next_ = (next_ + 1) % slots_.size();
}

size_t LateTimer::finished(const std::function<void(uint64_t, double)>& use) {
  size_t n = 0;
  for (size_t k = 0; k < slots_.size(); ++k) {
    Slot& s = slots_[(next_ + k) % slots_.size()];
    if (!s.busy) continue;
    if (!s.timer->ready()) break;
    s.busy = false;
    use(s.frame, s.timer->elapsedMs());
    ++n;
  }
  return n;
}

}  // namespace farfield::gpu
