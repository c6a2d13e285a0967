// SPDX-License-Identifier: MIT
// GLSL ES 3.00 sources of the renderer's passes.
#pragma once

namespace wingman::sim::detail {

/// Drones into the pinhole layer: camera-frame vertices (propellers posed per part), premultiplied linear colour
/// to attachment 0, the drone's id to attachment 1.
extern const char* const kDroneVertexShader;
extern const char* const kDroneFragmentShader;

/// A triangle that covers the viewport (no vertex buffers; gl_VertexID 0..2).
extern const char* const kFullscreenVertexShader;

/// Fragment shaders are assembled as "#version 300 es", the variant's #define lines, then kFragmentPreamble,
/// kLensFunctions, kSensorFunctions and the shader.
/// Defines: BG (background subsampling), SS (supersampling per axis), SCENE, CLOUDS, GROUND, TREES, NOISE, LAYER,
/// FINAL (0 or 1).

/// Precision statements.
extern const char* const kFragmentPreamble;
/// The lens map lookup: Corners corners(ivec2 px).
extern const char* const kLensFunctions;
/// The sensor stage: vec4 sensor(vec3 linear, ivec2 px, vec2 centre, bool in_view) -> 8-bit colour, drone id.
extern const char* const kSensorFunctions;

/// The background pass: per BG x BG block of camera pixels (BG = background_subsampling), the sky, clouds, ground
/// and treeline along the block's central ray, linear RGB. Variants SCENE, CLOUDS, GROUND, TREES. Assembled without
/// kLensFunctions and kSensorFunctions.
extern const char* const kBackgroundFragmentShader;

/// Per camera pixel: the background pass (interpolated) and, with LAYER 1, the drone layer over it, sampled at
/// SS^2 points through the lens map (drawn only where drones are, after a LAYER 0 pass over the whole image).
/// FINAL 1: through the sensor stage to the output; FINAL 0: weighted for motion-blur accumulation (LAYER 1 then
/// writes the difference the drones make, added to the LAYER 0 pass's).
extern const char* const kComposeFragmentShader;

/// The sensor stage on the accumulated motion-blur samples. Needs kLensFunctions and kSensorFunctions before it.
extern const char* const kFinalFragmentShader;

}  // namespace wingman::sim::detail
