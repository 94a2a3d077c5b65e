// The crowd's built-in person: a low-poly skinned humanoid with a looping walk cycle, made in memory (no file), so
// that a crowd needs no glTF model (eval::builtinCrowdModels).
//
// Figure space: metres, Z up, the front +x, the left +y, the feet on z = 0 at every key of the walk, about 1.77 m
// tall. Skeleton: 16 joints, each its own node, the hips the root: hips, spine, chest, head, upper_arm.L,
// forearm.L (the elbow), hand.L, the same .R, thigh.L, shin.L (the knee), foot.L (the ankle), the same .R.
// Parts: tubes for the legs, torso, neck, head, hair and arms, boxes for the pelvis, hands, shoes and nose (about 500
// triangles), each vertex following one joint or blending two at the knees, elbows, hips and waist.
// Colour regions (materials, each with its colour in the palette texture): kWalkerSkin (head, neck, hands, nose),
// kWalkerHair, kWalkerTop (torso and arms), kWalkerTrousers (pelvis and legs), kWalkerShoes.
// Animation "walk", kWalkerCycleSeconds long: each thigh swings +-22 degrees about y (the left leg forward in the
// first half of the cycle, the right leg in the second), the knee bends up to 50 degrees in the swing, each arm
// swings +-18 degrees opposite to the leg of its side with the elbow bent, the hips turn +-5 degrees about z and the
// chest against them, and the hips rise and fall twice a cycle (a few centimetres) so that the lower foot stays on
// the ground. At 1.3 m/s (the crowd's nominal speed) a cycle covers about the figure's stride (1.5 m).
#pragma once

#include <cstdint>

#include "farfield/scene/skin.h"

namespace farfield::gen {

inline constexpr float kWalkerCycleSeconds = 1.15f;
inline constexpr uint8_t kWalkerSkin = 0;
inline constexpr uint8_t kWalkerHair = 1;
inline constexpr uint8_t kWalkerTop = 2;
inline constexpr uint8_t kWalkerTrousers = 3;
inline constexpr uint8_t kWalkerShoes = 4;

// The walker, named "builtin:walker"; the same every call.
scene::SkinnedModel makeWalkerFigure();

}  // namespace farfield::gen
