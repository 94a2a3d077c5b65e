#version 450 core
// Farfield GPU crowd (gpu/gpu_crowd.h; issue 45): with FF_SIMULATE, each agent's pose at time u_time along its
// sidewalk loop (the arithmetic of gen::agentPose; the ground's height interpolated between the loop's points) and
// its animation phase (the distance walked over its model's stride, as eval's crowdAgentStates); otherwise, each agent culled by the camera's frustum (a sphere
// about its feet) and classified by its model's switch distance, its index appended to its model's geometry or
// impostor list, whose indirect draw command counts it.
// Under a geometry budget (GpuCrowd::setGeometryBudget; u_budget > 0) the classifying pass does not append the agents
// inside their switch distance: it marks them as candidates with their distance bucket and adds their model's
// triangles to that bucket's sum; FF_BUDGET_SCAN then finds the first bucket whose running sum passes the budget, and
// FF_BUDGET_ASSIGN appends the candidates nearer than it as geometry and the others as impostors ("over budget"): the
// nearest agents keep their geometry, and the skinned triangles stay within the budget.

layout(local_size_x = 64) in;

struct Agent {
  uint route, model, outfit, id;
  float start, speed, direction, phase;
  vec4 tint;
};
struct Route {
  uint first, count;  // loop points points[first .. first + count)
  float len, unused;
};
struct Model {
  vec4 sphere;        // centre (agent space: feet at the origin, facing +x, z up) and radius
  vec4 lists;         // x: this model's first list (geometry; impostors x + 1), y: stride (metres a walk cycle),
                      // z: the mesh's triangles, w: levels of detail (1: the mesh alone)
  uvec4 counts;       // palette poses, atlas frames, azimuths, elevations
  vec4 grid;          // x: the views' largest elevation (radians)
  vec4 level_m[2];    // per level (0..7): its error (runtime::CrowdRuntime::levelDistances; agent metres; level 0: 0)
  uvec4 level_tris[2];  // per level: its triangles
};
// An agent as the crowd renderer's shaders read it (gpu::CrowdAgentGpu, 48 bytes).
struct Record {
  vec4 pos_heading;
  vec4 tint;
  uvec4 misc;         // index (pose or frame), view, object id, outfit
};
struct Command {
  uint count, instance_count, first_index;
  int base_vertex;
  uint base_instance;
};

layout(std430, binding = 0) readonly buffer Agents { Agent agents[]; };
layout(std430, binding = 1) readonly buffer Routes { Route routes[]; };
layout(std430, binding = 2) readonly buffer Points { vec4 points[]; };  // x, y, arc length at the point, z (ground)
// Each pass declares the blocks it uses, readonly where it only reads them: what a pass may write is what the
// barrier check (gl_barrier_check.h) follows, so the simulation, which writes poses and phases alone, must not
// declare the lists that the last frame's draws read.
#ifdef FF_SIMULATE
layout(std430, binding = 3) writeonly buffer Poses { vec4 poses[]; };   // per agent: feet x y z, heading
layout(std430, binding = 4) writeonly buffer Phases { float phases[]; };  // per agent: animation phase [0, 1)
#else
layout(std430, binding = 3) readonly buffer Poses { vec4 poses[]; };
layout(std430, binding = 4) readonly buffer Phases { float phases[]; };
layout(std430, binding = 6) buffer Commands { Command commands[]; };   // per list
layout(std430, binding = 7) buffer Lists { Record lists[]; };          // per list, u_capacity agents
#endif
layout(std430, binding = 5) readonly buffer Models { Model models[]; };

uniform uint u_agents;
uniform float u_time;
uniform vec4 u_planes[6];      // frustum planes (dot(xyz, p) + w >= 0 inside)
uniform vec3 u_eye;
uniform float u_switch[16];    // per model: geometry nearer than this (metres)
uniform uint u_capacity;       // agents a list holds
// Occlusion (GpuCrowd::occludeBehind): the target's depth pyramid, and the camera that projects agents into it.
// in view, of them left out behind the depth; under a budget: the first bucket over it, candidates over it, the
// triangles kept, the triangles wanted; with levels of detail, the agents past their level's part of the list
#ifndef FF_SIMULATE
layout(std430, binding = 8) buffer Stats { uint stats[]; };
#endif
layout(binding = 2) uniform sampler2D u_depth;               // level 0: the target's depth
layout(binding = 3) uniform sampler2D u_pyramid;             // levels 1.. in its mips 0..
uniform int u_occlusion;
uniform mat4 u_view_proj;
uniform int u_levels;
uniform ivec2 u_level_size[16];
// Shadow casters (GpuCrowd::castShadows): the map's orthographic view-projection, its scale (x: 2 / side, per metre
// across the light; y: 1 / depth range), the direction towards the light, and where the casters' lists start.
uniform mat4 u_light_view_proj;
uniform vec2 u_light_scale;
uniform vec3 u_to_light;
uniform uint u_first_list;
// The geometry budget: skinned triangles a frame (0: none), and the candidates' distance buckets.
#ifndef FF_SIMULATE
layout(std430, binding = 9) buffer Candidates { uint candidates[]; };  // per agent: its bucket, or kNone
layout(std430, binding = 10) buffer Buckets { uint buckets[]; };       // per bucket: the candidates' triangles
#endif
uniform uint u_budget;
uniform uint u_buckets;
uniform float u_buckets_per_m;
const uint kNone = 0xFFFFFFFFu;
// Levels of detail (GpuCrowd::setLevelScale; u_lod_m_per_m > 0): a skinned agent takes the coarsest level whose
// error (level_m) is at most u_lod_m_per_m times its distance (runtime::CrowdRuntime::levelFor); level l of a
// model's geometry list holds u_level_capacity records from l * u_level_capacity, counted in level_counts (model * 8
// + level; the casters' from 16 * 8) and written into the commands by FF_LEVEL_COUNTS; an agent past a level's
// capacity is an impostor.
const uint kMaxLevels = 8u;
#ifndef FF_SIMULATE
layout(std430, binding = 11) buffer LevelCounts { uint level_counts[]; };
#endif
uniform float u_lod_m_per_m;
uniform uint u_level_capacity;
uniform uint u_level_command0;  // the command of level 1 of model 0; model m's level l: + m * 7 + l - 1 (the
                                // casters' after the camera's: + u_models * 7)
uniform uint u_models;

const float kTwoPi = 6.28318530717958647692;

// runtime/crowd_runtime.cpp's turn(): v turned by `heading` about +z.
vec3 turn(float heading, vec3 v) {
  float c = cos(heading), s = sin(heading);
  return vec3(c * v.x - s * v.y, s * v.x + c * v.y, v.z);
}

// The runtime's cycleIndex: the nearest of `count` poses or frames over one cycle.
uint cycleIndex(float phase, uint count) { return uint(floor((phase - floor(phase)) * float(count) + 0.5)) % count; }

vec3 viewDirection(Model m, uint cell) {
  float az = kTwoPi * float(cell % m.counts.z) / float(m.counts.z);
  float el = m.grid.x * float(cell / m.counts.z) / float(m.counts.w);
  return vec3(cos(el) * cos(az), cos(el) * sin(az), sin(el));
}

// impostor::nearestView for an azimuth x elevation grid (not octahedral).
uint nearestView(Model m, vec3 to_camera) {
  vec3 d = normalize(to_camera);
  float az = atan(d.y, d.x);
  if (az < 0.0) az += kTwoPi;
  uint ai = uint(floor(az / kTwoPi * float(m.counts.z) + 0.5)) % m.counts.z;
  float el = asin(clamp(d.z, -1.0, 1.0));
  float step = m.grid.x / float(m.counts.w);
  int below = clamp(int(floor(el / step)), 0, int(m.counts.w) - 1);
  int above = min(below + 1, int(m.counts.w) - 1);
  uint a = uint(below) * m.counts.z + ai, b = uint(above) * m.counts.z + ai;
  return dot(viewDirection(m, a), d) >= dot(viewDirection(m, b), d) ? a : b;
}

// gpu::DepthPyramid::farthest: the farthest depth over the pixels [lo, hi], from the finest level where they span at
// most two texels each way.
float farthest(ivec2 lo, ivec2 hi) {
  lo = max(lo, ivec2(0));
  hi = min(hi, u_level_size[0] - 1);
  if (lo.x > hi.x || lo.y > hi.y) return 1.0;
  int k = 0;
  while (k + 1 < u_levels && ((hi.x >> k) - (lo.x >> k) > 1 || (hi.y >> k) - (lo.y >> k) > 1)) ++k;
  float result = 1e30;
  for (int y = lo.y >> k; y <= (hi.y >> k); ++y)
    for (int x = lo.x >> k; x <= (hi.x >> k); ++x)
      result = min(result, k == 0 ? texelFetch(u_depth, ivec2(x, y), 0).r : texelFetch(u_pyramid, ivec2(x, y), k - 1).r);
  return result;
}

// gpu::projectBox and DepthPyramid::hides for the cube about the sphere (runtime::CrowdRuntime::hidden's box).
bool hidden(vec3 c, float r) {
  vec2 size = vec2(u_level_size[0]);
  vec2 lo = vec2(1e30), hi = vec2(-1e30);
  float nearest = -1e30;
  for (int k = 0; k < 8; ++k) {
    vec3 corner = c + r * vec3((k & 1) != 0 ? 1.0 : -1.0, (k & 2) != 0 ? 1.0 : -1.0, (k & 4) != 0 ? 1.0 : -1.0);
    vec4 clip = u_view_proj * vec4(corner, 1.0);
    if (!(clip.w > 1e-6)) return false;  // reaches the eye
    vec2 p = (clip.xy / clip.w * 0.5 + 0.5) * size;
    lo = min(lo, p);
    hi = max(hi, p);
    nearest = max(nearest, clip.z / clip.w);
  }
  ivec2 x0 = ivec2(max(ivec2(0), ivec2(floor(max(lo, vec2(-2.0)))) - 1));
  ivec2 x1 = ivec2(min(u_level_size[0] - 1, ivec2(floor(min(hi, size + 1.0))) + 1));
  if (x0.x > x1.x || x0.y > x1.y) return true;  // in front of the eye, no pixel centre covered
  return nearest * (1.0 + 1e-5) + 1e-12 < farthest(x0, x1);
}

// The direction to the eye in agent space from an agent at `pose` whose sphere is centred at c (the impostor view's).
vec3 eyeInAgentSpace(vec4 pose, vec3 c) {
  vec3 local = turn(-pose.w, u_eye - c);
  return length(local) > 0.0 ? local : vec3(1.0, 0.0, 0.0);
}

// The level of detail of a skinned agent at distance d (metres) from the eye.
uint levelOf(Model m, float d) {
  uint level = 0u;
  if (u_lod_m_per_m > 0.0) {
    float allowed = u_lod_m_per_m * d;
    for (uint l = 1u; l < uint(m.lists.w); ++l)
      if (m.level_m[l / 4u][l % 4u] <= allowed) level = l;
  }
  return level;
}

// A skinned agent's triangles at distance d (what the budget counts).
uint geometryTriangles(Model m, float d) {
  uint l = levelOf(m, d);
  return m.level_tris[l / 4u][l % 4u];
}

#ifndef FF_SIMULATE
// Agent i as the renderer's record: the palette pose or the atlas frame nearest its phase, and for an impostor the
// view nearest `view_dir` (agent space).
Record recordOf(uint i, Agent a, Model m, vec4 pose, vec3 view_dir, bool impostor) {
  Record r;
  r.pos_heading = pose;
  r.tint = a.tint;
  uint index = cycleIndex(phases[i], impostor ? m.counts.y : m.counts.x);
  uint view = impostor ? nearestView(m, view_dir) : 0u;
  r.misc = uvec4(index, view, a.id, a.outfit);
  return r;
}

// Agent i into its model's geometry or impostor list after `first_list`.
void append(uint first_list, uint i, Agent a, Model m, vec4 pose, vec3 view_dir, bool impostor) {
  uint list = first_list + uint(m.lists.x) + (impostor ? 1u : 0u);
  uint slot = atomicAdd(commands[list].instance_count, 1u);
  lists[list * u_capacity + slot] = recordOf(i, a, m, pose, view_dir, impostor);
}

// Where the level counters of the lists after first_list start (the camera's or the casters').
uint counterBase(uint first_list) { return first_list == 0u ? 0u : 16u * kMaxLevels; }

// Agent i, inside its switch at distance d from the eye, into the lists after first_list (the camera's or the
// casters') as geometry: with levels of detail, into its level's part of the geometry list (an impostor when that
// part is full; the camera's counted in stats[6]).
void appendGeometry(uint first_list, uint i, Agent a, Model m, vec4 pose, vec3 view_dir, float d) {
  if (!(u_lod_m_per_m > 0.0)) {
    append(first_list, i, a, m, pose, view_dir, false);
    return;
  }
  uint level = levelOf(m, d);
  uint slot = atomicAdd(level_counts[counterBase(first_list) + a.model * kMaxLevels + level], 1u);
  if (slot >= u_level_capacity) {
    if (first_list == 0u) atomicAdd(stats[6], 1u);
    append(first_list, i, a, m, pose, view_dir, true);
    return;
  }
  lists[(first_list + uint(m.lists.x)) * u_capacity + level * u_level_capacity + slot] =
      recordOf(i, a, m, pose, view_dir, false);
}
#endif

#if defined(FF_SIMULATE)
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_agents) return;
  Agent a = agents[i];
  Route r = routes[a.route];
  float walked = a.speed * u_time;
  float s = mod(a.start + a.direction * walked, r.len);
  if (s < 0.0) s += r.len;
  // The segment: the last point whose arc length is at most s (binary search).
  uint lo = 0u, hi = r.count;  // points[first + lo].z <= s < points[first + hi].z
  while (hi - lo > 1u) {
    uint mid = (lo + hi) / 2u;
    if (points[r.first + mid].z <= s) lo = mid; else hi = mid;
  }
  vec4 p0 = points[r.first + lo], p1 = points[r.first + (lo + 1u) % r.count];
  vec2 d = p1.xy - p0.xy;
  float len = length(d);
  vec2 dir = len > 0.0 ? d / len : vec2(1.0, 0.0);
  float along = clamp(s - p0.z, 0.0, len);
  vec2 p = p0.xy + dir * along;
  float z = len > 0.0 ? mix(p0.w, p1.w, along / len) : p0.w;
  vec2 walk = dir * a.direction;
  poses[i] = vec4(p, z, atan(walk.y, walk.x));
  phases[i] = fract(a.phase + walked / models[a.model].lists.y);
}
#elif defined(FF_CASTERS)
// FF_CASTERS: the agents whose sphere reaches into the shadow map's box cast, in the representation the camera's
// switch gives them; under a geometry budget (u_budget != 0: the last classification had one), as the camera draws
// them: geometry only where the budget kept it, and an agent not drawn (out of view, hidden) as an impostor
// (runtime::CrowdRuntime::castsAsImpostor). Impostors show their view towards the light.
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_agents) return;
  Agent a = agents[i];
  Model m = models[a.model];
  vec4 pose = poses[i];
  vec3 c = pose.xyz + turn(pose.w, m.sphere.xyz);
  float r = m.sphere.w;
  vec4 p = u_light_view_proj * vec4(c, 1.0);  // orthographic: w = 1
  if (abs(p.x) > 1.0 + r * u_light_scale.x || abs(p.y) > 1.0 + r * u_light_scale.x || p.z < -r * u_light_scale.y ||
      p.z > 1.0 + r * u_light_scale.y)
    return;
  float d = distance(u_eye, c);
  bool impostor = !(d < u_switch[a.model]);
  if (u_budget != 0u) impostor = candidates[i] == kNone || candidates[i] >= stats[2];
  vec3 view_dir = turn(-pose.w, u_to_light);
  if (impostor) append(u_first_list, i, a, m, pose, view_dir, true);
  else appendGeometry(u_first_list, i, a, m, pose, view_dir, d);  // at the level the camera draws it
}
#elif defined(FF_BUDGET_SCAN)
// One invocation: the first bucket whose running sum of triangles passes the budget (u_buckets: none does), the
// triangles kept and wanted; the buckets cleared for the next frame.
void main() {
  if (gl_GlobalInvocationID.x != 0u) return;
  uint kept = 0u, wanted = 0u, first_over = u_buckets;
  for (uint b = 0u; b < u_buckets; ++b) {
    uint t = buckets[b];
    wanted += t;
    if (first_over == u_buckets) {
      if (t > u_budget - kept) first_over = b;
      else kept += t;
    }
    buckets[b] = 0u;
  }
  stats[2] = first_over;
  stats[4] = kept;
  stats[5] = wanted;
}
#elif defined(FF_BUDGET_ASSIGN)
// The candidates nearer than the first bucket over the budget as geometry, the others as impostors.
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_agents) return;
  uint bucket = candidates[i];
  if (bucket == kNone) return;
  Agent a = agents[i];
  Model m = models[a.model];
  vec4 pose = poses[i];
  vec3 c = pose.xyz + turn(pose.w, m.sphere.xyz);
  bool impostor = bucket >= stats[2];
  if (impostor) {
    atomicAdd(stats[3], 1u);
    append(0u, i, a, m, pose, eyeInAgentSpace(pose, c), true);
  } else {
    appendGeometry(0u, i, a, m, pose, eyeInAgentSpace(pose, c), distance(u_eye, c));
  }
}
#elif defined(FF_LEVEL_COUNTS)
// One invocation: each level's count of the lists after u_first_list (the camera's or the casters'), at most its
// part of the list, into its command; the counts cleared.
void main() {
  if (gl_GlobalInvocationID.x != 0u) return;
  uint base = counterBase(u_first_list);
  uint levels = u_level_command0 + (u_first_list == 0u ? 0u : u_models * (kMaxLevels - 1u));
  for (uint mo = 0u; mo < u_models; ++mo)
    for (uint l = 0u; l < kMaxLevels; ++l) {
      uint command = l == 0u ? u_first_list + 2u * mo : levels + mo * (kMaxLevels - 1u) + l - 1u;
      commands[command].instance_count = min(level_counts[base + mo * kMaxLevels + l], u_level_capacity);
      level_counts[base + mo * kMaxLevels + l] = 0u;
    }
}
#else
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_agents) return;
  if (u_budget != 0u) candidates[i] = kNone;
  Agent a = agents[i];
  Model m = models[a.model];
  vec4 pose = poses[i];
  // The runtime's bounding sphere: the model's centre turned by the heading, about the feet (normalised planes).
  vec3 c = pose.xyz + turn(pose.w, m.sphere.xyz);
  for (int k = 0; k < 6; ++k)
    if (dot(u_planes[k].xyz, c) + u_planes[k].w < -m.sphere.w) return;
  atomicAdd(stats[0], 1u);
  if (u_occlusion != 0 && hidden(c, m.sphere.w)) {
    atomicAdd(stats[1], 1u);
    return;
  }
  float d = distance(u_eye, c);
  bool impostor = !(d < u_switch[a.model]);
  if (u_budget != 0u && !impostor) {  // a candidate for geometry: FF_BUDGET_ASSIGN decides
    uint bucket = min(uint(d * u_buckets_per_m), u_buckets - 1u);
    candidates[i] = bucket;
    atomicAdd(buckets[bucket], geometryTriangles(m, d));
    return;
  }
  if (impostor) append(0u, i, a, m, pose, eyeInAgentSpace(pose, c), true);
  else appendGeometry(0u, i, a, m, pose, eyeInAgentSpace(pose, c), d);
}
#endif
