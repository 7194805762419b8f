// The constants of shaders/accumulate.comp; Rust twins: shine::passes::accumulate
// (ACCUMULATE_MIN_WEIGHT, TAA_STILL_PIXELS, TAA_MOVING_FRAMES, TAA_MIN_INVERSE), tied by
// tests/shader_constants.rs. TAA's blend space is x / (1 + luminance(x)) (color.glsl).
#ifndef ACCUMULATE_GLSL
#define ACCUMULATE_GLSL
#include "color.glsl"

// Smallest bilinear weight of a pixel's history taps that show its surface: below it the
// history is rejected (disocclusion) and restarts.
const float ACCUMULATE_MIN_WEIGHT = 0.01;

// The indirect light's history restarts where the clip moved it by more than this share of
// its luminance and the view holds still (issue 43): the light changed beyond the
// neighbourhood's noise (a light switched off), and a history that kept counting would trail
// it.
const float ACCUMULATE_CHANGE = 0.5;

// Least luminance the temporal σ is spread over (the neighbourhood's colour of a black
// neighbourhood is undefined).
const float ACCUMULATE_MIN_LUMINANCE = 1e-6;

// What the filter state's RGBA16F texel holds: the trend within ±HALF_MAX, the variance at
// most HALF_MAX (inf would turn into NaN in the next frame's blend).
vec4 accumulate_storable(vec4 v) {
    return clamp(v, vec4(-HALF_MAX), vec4(HALF_MAX));
}

// Motion (pixels) below which TAA counts a pixel as still: its history may show any surface
// of its 3×3 neighbourhood.
const float TAA_STILL_PIXELS = 0.01;

// Longest history of a moving pixel under TAA.
const float TAA_MOVING_FRAMES = 2.0;

// Smallest 1 - luma of a blend-space value when it is mapped back (its luma is below 1 for
// every finite radiance; this keeps rounding from dividing by 0).
const float TAA_MIN_INVERSE = 1e-4;

#endif
