#version 450 core
// Farfield cluster culling (gpu/gpu_culler.h), in stages compiled from this one file (FF_STAGE_*):
//   PARTS (one invocation per part of the plan's objects: every part, or those of part_list), by phase: 0 (early)
//     parts of objects in this frame's plan whose box meets the frustum are in view, and those visible in the last
//     frame put their cluster instances on the work list; 1 (late) parts in view whose box the depth pyramid does
//     not hide put theirs; 2 (no occlusion) every part in view puts its instances; the others are culled whole;
//   CLUSTERS (one per work list entry): an instance is in view when its sphere and box meet the frustum and its normal
//     cone does not turn every triangle away from the eye; then, by phase,
//       0 (early): those in view that were visible in the last frame are drawn,
//       1 (late): those in view are tested against the depth pyramid built from the early phase's depth; those not
//         hidden are visible, and drawn unless the early phase drew them; the visibility is kept for the next frame,
//       2 (all): those in view are drawn (no occlusion) and are the visible ones,
//       3 (history, over the instances drawn in this frame, whose list phases 0 and 1 keep): those not hidden by the
//         pyramid of the frame's final depth are the visible ones the next frame's early phase draws (without it, a
//         cluster drawn late stays "visible" when later clusters hid it, and after a camera cut the next frame draws
//         everything in view first); the others are no longer visible;
//   EMIT (one per work list entry): each run of consecutive drawn clusters of one object part (contiguous indices)
//     becomes one indirect draw command, compacted per material group (an atomic counter per group, drawn with
//     glMultiDrawElementsIndirectCount) or in its first instance's own slot (the other slots cleared).
// A list's indirect dispatch (the work list's for CLUSTERS and EMIT, the drawn list's for phase 3) grows with it as
// entries are appended (startsGroup, listDispatch), so no stage of its own turns a length into a dispatch between them.
// The occlusion test is gpu::OcclusionCuller's (occlusion_culler.cpp: projectBox, DepthPyramid::farthest, hides),
// the same conservative arithmetic: a box is hidden only when all of it lies behind the stored depth at every pixel
// it may cover.

layout(local_size_x = 64) in;

struct Cluster {
  vec4 sphere;     // centre, radius (mesh space)
  vec4 cone_apex;  // xyz, w = cutoff
  vec4 cone_axis;
  vec4 box_lo;
  vec4 box_hi;
  uvec4 range;     // first index, index count, base vertex
};
struct Object {
  mat4 model;
  mat4 normal_matrix;
  vec4 misc;   // x: largest axis scale; y, z: the least and the most it stretches lengths (objectStretch)
  uvec4 info;  // id, flags (1: affine)
};
struct Command {
  uint count;
  uint instance_count;
  uint first_index;
  int base_vertex;
  uint base_instance;
};
struct Part {
  uvec4 info;   // object, first instance, instance count, simplified level's instance count (after the full ones)
  vec4 box_lo;  // of its mesh, in the object's own space; w: the simplified level's error (mesh units)
  vec4 box_hi;
};

layout(std430, binding = 0) readonly buffer Clusters { Cluster clusters[]; };
layout(std430, binding = 1) readonly buffer Instances { uvec4 instances[]; };  // cluster, object, material, group
layout(std430, binding = 2) readonly buffer Objects { Object objects[]; };
layout(std430, binding = 4) readonly buffer Enabled { uint enabled[]; };        // per object: drawn in the plan
// Declared in the stages that use them, readonly where a stage only reads (the barrier check, gl_barrier_check.h,
// takes a block not declared readonly as written): an implementation may also count every declared block against its
// limit of storage blocks per compute shader (16 on llvmpipe).
#ifdef FF_STAGE_CLUSTERS
layout(std430, binding = 5) buffer Visibility { uint visible[]; };              // per instance: visible last frame
#endif
#ifdef FF_STAGE_EMIT
layout(std430, binding = 6) buffer Commands { Command commands[]; };
layout(std430, binding = 7) buffer Counts { uint counts[]; };                   // per group: commands written
layout(std430, binding = 8) readonly buffer GroupFirst { uint group_first[]; };
#endif
layout(std430, binding = 9) buffer Stats { uint stats[]; };
#ifdef FF_STAGE_CLUSTERS
layout(std430, binding = 10) buffer ObjectFrame { uint object_frame[]; };    // per object: last frame it was drawn
#endif
layout(std430, binding = 11) readonly buffer Parts { Part parts[]; };
#ifdef FF_STAGE_PARTS
layout(std430, binding = 12) buffer Work { uvec4 dispatch_args; uint work[]; };  // dispatch_args.w: list length
#else
layout(std430, binding = 12) readonly buffer Work { uvec4 dispatch_args; uint work[]; };
#endif
#ifdef FF_STAGE_CLUSTERS
layout(std430, binding = 13) buffer Drawn { uint drawn_flag[]; };            // per instance: drawn in this phase
layout(std430, binding = 14) buffer DrawnList { uvec4 drawn_args; uint drawn_list[]; };  // instances drawn this frame
#elif defined(FF_STAGE_EMIT)
layout(std430, binding = 13) readonly buffer Drawn { uint drawn_flag[]; };
#endif
// Per part: bit 0 visible in the last frame (a cluster of it visible in its final depth), bit 1 in view this frame,
// bit 2 on this frame's early list (its clusters visible in the last frame drawn early: a cluster's own flag alone
// may be older than its part's, from a frame before the part was hidden).
#ifndef FF_STAGE_EMIT
layout(std430, binding = 15) buffer PartVisible { uint part_visible[]; };
#endif
layout(std430, binding = 16) readonly buffer InstancePart { uint instance_part[]; };
#ifdef FF_STAGE_PARTS
layout(std430, binding = 17) readonly buffer PartList { uint part_list[]; };  // with u_listed: the plan's parts
#endif

layout(binding = 2) uniform sampler2D u_depth;    // pyramid level 0: the frame's depth
layout(binding = 3) uniform sampler2D u_pyramid;  // levels 1.. in its mip levels 0..

uniform mat4 u_view_proj;
uniform vec4 u_planes[6];
uniform vec3 u_eye;
uniform ivec2 u_viewport;
uniform int u_phase;
uniform int u_compact;
uniform int u_cone;
uniform uint u_count;    // PARTS: parts (the listed ones with u_listed); the instances of the arena otherwise
uniform int u_listed;    // PARTS: 1 when the invocations take the parts of part_list (the plan's), 0 every part
uniform int u_levels;
uniform ivec2 u_level_size[16];
uniform float u_margin;  // relative depth margin of the occlusion test
uniform uint u_frame;    // this frame's number + 1 (object_frame starts at 0)
uniform float u_lod_px;     // PARTS: the simplified levels' bound in pixels (0: never)
uniform float u_lod_scale;  // PARTS: pixels per unit of error at distance 1

// Statistics (gpu_culler.cpp, GpuCullStats): summed in shared memory, added once per work group.
const int kInPlan = 0, kDrawnEarly = 1, kDrawnLate = 2, kTrianglesEarly = 3, kTrianglesLate = 4, kFrustum = 5,
          kCone = 6, kOccluded = 7, kObjects = 8, kCommands = 9, kStatCount = 10;
shared uint s_stats[kStatCount];

void beginStats() {
  if (gl_LocalInvocationIndex < uint(kStatCount)) s_stats[gl_LocalInvocationIndex] = 0u;
  barrier();
}
void endStats() {
  barrier();
  if (gl_LocalInvocationIndex < uint(kStatCount) && s_stats[gl_LocalInvocationIndex] != 0u)
    atomicAdd(stats[gl_LocalInvocationIndex], s_stats[gl_LocalInvocationIndex]);
}
uint invocation() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
}

// The work groups (x, y) of a list of `length` entries: 64 a group, those past 65535 into y (kMaxGroupsX).
uvec2 listDispatch(uint length) {
  const uint groups = (length + 63u) / 64u;
  return uvec2(min(groups, 65535u), (groups + 65534u) / 65535u);
}
// Whether entries [from, to) of a list start a work group: their appender then raises the list's dispatch to
// listDispatch(to). The appender of the entry that starts the last group does so with the largest count of groups,
// so the dispatch covers the list once every appender is done; the others leave it alone.
bool startsGroup(uint from, uint to) {
  return (from + 63u) / 64u != (to + 63u) / 64u;
}

// The box [lo, hi] of an object's own space under `model` against the frustum (Frustum::intersects, with each plane
// taken into that space): false only when it certainly lies outside.
bool boxInFrustum(vec3 lo, vec3 hi, mat4 model) {
  for (int p = 0; p < 6; ++p) {
    const vec4 local = u_planes[p] * model;
    const vec3 corner = vec3(local.x >= 0.0 ? hi.x : lo.x, local.y >= 0.0 ? hi.y : lo.y, local.z >= 0.0 ? hi.z : lo.z);
    if (dot(local.xyz, corner) + local.w < 0.0) return false;
  }
  return true;
}

float levelTexel(int k, ivec2 p) {
  return k == 0 ? texelFetch(u_depth, p, 0).r : texelFetch(u_pyramid, p, k - 1).r;
}

// DepthPyramid::farthest over the pixels [x0, x1] x [y0, y1] (inside the image, not empty).
float farthest(int x0, int y0, int x1, int y1) {
  int k = 0;
  while (k + 1 < u_levels && ((x1 >> k) - (x0 >> k) > 1 || (y1 >> k) - (y0 >> k) > 1)) ++k;
  float result = 3.0e38;
  for (int y = y0 >> k; y <= (y1 >> k); ++y)
    for (int x = x0 >> k; x <= (x1 >> k); ++x) result = min(result, levelTexel(k, ivec2(x, y)));
  return result;
}

// projectBox + DepthPyramid::hides.
bool hidden(vec3 lo, vec3 hi, mat4 mvp) {
  float min_x = 3.0e38, min_y = 3.0e38, max_x = -3.0e38, max_y = -3.0e38, nearest = -3.0e38;
  for (int i = 0; i < 8; ++i) {
    const vec3 corner = vec3((i & 1) != 0 ? hi.x : lo.x, (i & 2) != 0 ? hi.y : lo.y, (i & 4) != 0 ? hi.z : lo.z);
    const vec4 clip = mvp * vec4(corner, 1.0);
    if (!(clip.w > 1e-6)) return false;  // reaches the eye: never hidden
    const float x = (clip.x / clip.w * 0.5 + 0.5) * float(u_viewport.x);
    const float y = (clip.y / clip.w * 0.5 + 0.5) * float(u_viewport.y);
    min_x = min(min_x, x), max_x = max(max_x, x);
    min_y = min(min_y, y), max_y = max(max_y, y);
    nearest = max(nearest, clip.z / clip.w);
  }
  const int x0 = max(0, int(floor(max(min_x, -2.0))) - 1);
  const int y0 = max(0, int(floor(max(min_y, -2.0))) - 1);
  const int x1 = min(u_viewport.x - 1, int(floor(min(max_x, float(u_viewport.x) + 1.0))) + 1);
  const int y1 = min(u_viewport.y - 1, int(floor(min(max_y, float(u_viewport.y) + 1.0))) + 1);
  if (x0 > x1 || y0 > y1) return true;  // in front of the eye and covering no pixel centre
  return nearest * (1.0 + u_margin) + 1e-12 < farthest(x0, y0, x1, y1);
}


#if defined(FF_STAGE_PARTS)
// The instances this frame draws the part with: its simplified level's when that level's error, at the distance from
// the eye to the part's box, projects to at most u_lod_px (partLodErrorPx, scene_arena.cpp), else the full level's.
// The same in every phase of a frame.
uvec2 partRange(Part part, bool affine, uint object) {
  const uvec2 full = uvec2(part.info.y, part.info.z);
  const float least = objects[object].misc.y, most = objects[object].misc.z;
  if (!(u_lod_px > 0.0) || part.info.w == 0u || !affine || !(least > 0.0)) return full;
  const mat4 model = objects[object].model;
  // The eye in the object's space: the inverse of the linear part is the transpose of the normal matrix.
  const vec3 local = transpose(mat3(objects[object].normal_matrix)) * (u_eye - model[3].xyz);
  const vec3 gap = max(max(part.box_lo.xyz - local, local - part.box_hi.xyz), vec3(0.0));
  const float distance = length(gap) * least;
  if (!(distance > 0.0) || part.box_lo.w * most * u_lod_scale > u_lod_px * distance) return full;
  return uvec2(part.info.y + part.info.z, part.info.w);
}

// Appends the instances [range.x, + range.y) to the work list.
void appendPart(uvec2 range) {
  const uint base = atomicAdd(dispatch_args.w, range.y);
  for (uint k = 0u; k < range.y; ++k) work[base + k] = range.x + k;
  if (startsGroup(base, base + range.y)) {
    const uvec2 d = listDispatch(base + range.y);
    atomicMax(dispatch_args.x, d.x);
    atomicMax(dispatch_args.y, d.y);
  }
}

void main() {
  beginStats();
  const uint invoked = invocation();
  if (invoked < u_count) {
    const uint i = u_listed != 0 ? part_list[invoked] : invoked;
    const Part part = parts[i];
    const uint object = part.info.x;
    const bool affine = (objects[object].info.y & 1u) != 0u;
    const uvec2 range = partRange(part, affine, object);
    const uint count = range.y;
    if (u_phase == 0 || u_phase == 2) {
      // The frame's first look at the part: in the plan and in the frustum; the early list takes those visible in the
      // last frame, the only phase (2) all of them.
      bool in_view = enabled[object] != 0u && count > 0u;
      if (in_view) atomicAdd(s_stats[kInPlan], count);
      if (in_view && affine && !boxInFrustum(part.box_lo.xyz, part.box_hi.xyz, objects[object].model)) {
        in_view = false;
        atomicAdd(s_stats[kFrustum], count);
      }
      const bool early = in_view && u_phase == 0 && (part_visible[i] & 1u) != 0u;
      part_visible[i] = (part_visible[i] & 1u) | (in_view ? 2u : 0u) | (early ? 4u : 0u);
      if (early || (in_view && u_phase == 2)) appendPart(range);
    } else {
      // The late list: parts in view whose box the early phase's depth does not hide. A part of which a cluster was
      // drawn early is never hidden (that cluster's depth is inside its box).
      const uint state = part_visible[i];
      if ((state & 2u) != 0u) {
        const bool occluded = affine && hidden(part.box_lo.xyz, part.box_hi.xyz, u_view_proj * objects[object].model);
        part_visible[i] = (state & 6u) | (occluded ? 0u : 1u);
        if (occluded) atomicAdd(s_stats[kOccluded], count);
        else appendPart(range);
      }
    }
  }
  endStats();
}

#elif defined(FF_STAGE_CLUSTERS)
void main() {
  beginStats();
  const uint w = invocation();
  if (w < dispatch_args.w) {
    const uint i = work[w];
    const uvec4 instance = instances[i];
    const bool cone_test = u_cone != 0 && (instance.w & 0x80000000u) != 0u;
    const Cluster c = clusters[instance.x];
    const mat4 model = objects[instance.y].model;
    const bool affine = (objects[instance.y].info.y & 1u) != 0u;
    const bool counting = u_phase == 1 || u_phase == 2;  // the frame's statistics come from one pass
    bool in_view = true;
    if (affine) {
      const vec3 centre = (model * vec4(c.sphere.xyz, 1.0)).xyz;
      const float radius = c.sphere.w * objects[instance.y].misc.x;
      for (int p = 0; p < 6; ++p)
        if (dot(u_planes[p].xyz, centre) + u_planes[p].w < -radius) in_view = false;
      // The cluster's box too: tighter than the sphere for flat and long clusters.
      in_view = in_view && boxInFrustum(c.box_lo.xyz, c.box_hi.xyz, model);
      if (!in_view && counting) atomicAdd(s_stats[kFrustum], 1u);
    }
    if (in_view && cone_test) {
      // coneRejects (scene_arena.cpp), in world space: the transform keeps angles (SceneArena checks).
      const vec3 apex = (model * vec4(c.cone_apex.xyz, 1.0)).xyz;
      const vec3 axis = normalize(mat3(model) * c.cone_axis.xyz);
      const vec3 d = apex - u_eye;
      const float len = length(d);
      if (len > 0.0 && dot(d / len, axis) >= c.cone_apex.w + 1e-3) {
        in_view = false;
        if (counting) atomicAdd(s_stats[kCone], 1u);
      }
    }
    bool drawn = false;
    if (u_phase == 3) {
      // The history for the next frame: visible in this frame's final depth (the parts' bits cleared before).
      const bool now_visible = in_view && !(affine && hidden(c.box_lo.xyz, c.box_hi.xyz, u_view_proj * model));
      visible[i] = now_visible ? 1u : 0u;
      if (now_visible) atomicOr(part_visible[instance_part[i]], 1u);
    } else if (u_phase == 0) {
      drawn = in_view && visible[i] != 0u;
    } else if (u_phase == 1) {
      const bool occluded = in_view && affine && hidden(c.box_lo.xyz, c.box_hi.xyz, u_view_proj * model);
      const bool now_visible = in_view && !occluded;
      // What the early phase drew: a cluster visible in the last frame of a part on the early list.
      const bool early = (part_visible[instance_part[i]] & 4u) != 0u && visible[i] != 0u;
      drawn = now_visible && !(early && in_view);
      visible[i] = now_visible ? 1u : 0u;
      if (occluded) atomicAdd(s_stats[kOccluded], 1u);
    } else {
      drawn = in_view;
      visible[i] = in_view ? 1u : 0u;
    }
    if (u_phase != 3) drawn_flag[i] = drawn ? 1u : 0u;
    if (drawn) {
      const uint at = atomicAdd(drawn_args.w, 1u);
      drawn_list[at] = i;
      if (startsGroup(at, at + 1u)) {
        const uvec2 d = listDispatch(at + 1u);
        atomicMax(drawn_args.x, d.x);
        atomicMax(drawn_args.y, d.y);
      }
      atomicAdd(s_stats[u_phase == 0 ? kDrawnEarly : kDrawnLate], 1u);
      atomicAdd(s_stats[u_phase == 0 ? kTrianglesEarly : kTrianglesLate], c.range.y / 3u);
      // Distinct objects: the first instance of an object drawn in this frame counts it.
      if (atomicExchange(object_frame[instance.y], u_frame) != u_frame) atomicAdd(s_stats[kObjects], 1u);
    }
  }
  endStats();
}

#elif defined(FF_STAGE_EMIT)

// Whether instance b continues instance a in one draw: the same object, material, group and level (bit 30: the
// simplified level's), and b's indices right after a's over the same vertices (consecutive clusters of one part's
// level). Both are then on the work list together.
bool continues(uint a, uint b) {
  const uvec4 ia = instances[a], ib = instances[b];
  if (ia.y != ib.y || ia.z != ib.z || (ia.w & 0x4000ffffu) != (ib.w & 0x4000ffffu)) return false;
  const uvec4 ra = clusters[ia.x].range, rb = clusters[ib.x].range;
  return ra.z == rb.z && ra.x + ra.y == rb.x;
}

void main() {
  beginStats();
  const uint w = invocation();
  if (w < dispatch_args.w) {
    const uint i = work[w];
    if (drawn_flag[i] != 0u && !(i > 0u && continues(i - 1u, i) && drawn_flag[i - 1u] != 0u)) {
      // The head of a run: draw through its last drawn successor.
      const uvec4 range = clusters[instances[i].x].range;
      uint count = range.y;
      for (uint j = i; j + 1u < u_count && continues(j, j + 1u) && drawn_flag[j + 1u] != 0u; ++j)
        count += clusters[instances[j + 1u].x].range.y;
      const uint group = instances[i].w & 0xffffu;
      const uint slot = u_compact != 0 ? group_first[group] + atomicAdd(counts[group], 1u) : i;
      commands[slot] = Command(count, 1u, range.x, int(range.z), instance_part[i]);  // baseInstance: the part's row
      atomicAdd(s_stats[kCommands], 1u);
    }
  }
  endStats();
}
#endif
