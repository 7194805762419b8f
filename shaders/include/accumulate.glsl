// The constant of shaders/accumulate.comp; Rust twin: shine::passes::accumulate
// (ACCUMULATE_MIN_WEIGHT), tied by tests/shader_constants.rs.
#ifndef ACCUMULATE_GLSL
#define ACCUMULATE_GLSL

// Smallest bilinear weight of a pixel's history taps that show its surface: below it the
// history is rejected (disocclusion) and restarts.
const float ACCUMULATE_MIN_WEIGHT = 0.01;

#endif
