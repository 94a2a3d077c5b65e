// The crowd's built-in animal: a low-poly skinned four-legged figure (a dog or fox: body, head with snout and ears,
// four legs, a tail) with its own looping walk cycle, made in memory (no file), so that a crowd needs no glTF model
// (eval::builtinCrowdModels).
//
// Figure space: metres, Z up, the front +x, the left +y, the paws on z = 0 at every key of the walk, about 0.7 m to
// the ear tips. Skeleton: 18 joints, each its own node, the pelvis the root: pelvis, chest, neck, head, tail,
// tail_tip, and per leg (front.L, front.R, hind.L, hind.R) upper_<leg>, lower_<leg> (the elbow or knee) and
// paw_<leg>. Parts: tubes for the body, neck, head, snout, ears, legs and tail, boxes for the paws and nose (about
// 450 triangles), vertices blending two joints where the legs meet the body, at the knees and along the tail.
// Colour regions (materials, each with its colour in the palette texture): kQuadrupedFur (body, head, legs, tail),
// kQuadrupedPale (snout, the tail's tip), kQuadrupedDark (ears, nose, paws).
// Animation "walk", kQuadrupedCycleSeconds long: a four-beat walk, each leg swinging +-25 degrees about y a quarter
// cycle after the one before it (hind left, front left, hind right, front right), its lower joint bending in the
// swing; the tail raised and wagging, the head nodding twice a cycle, and the body riding so that the lowest paw
// stays on the ground. At 1.3 m/s a cycle covers about its stride (0.65 m).
#pragma once

#include <cstdint>

#include "farfield/scene/skin.h"

namespace farfield::gen {

inline constexpr float kQuadrupedCycleSeconds = 0.5f;
inline constexpr uint8_t kQuadrupedFur = 5;
inline constexpr uint8_t kQuadrupedPale = 6;
inline constexpr uint8_t kQuadrupedDark = 7;

// The four-legged figure, named "builtin:quadruped"; the same every call.
scene::SkinnedModel makeQuadrupedFigure();

}  // namespace farfield::gen
