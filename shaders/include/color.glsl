// Colour constants of linear Rec. 709 radiance. Rust twin: shine::capture::tonemap
// (REC709_LUMA, luminance), tied by tests/shader_constants.rs.
#ifndef COLOR_GLSL
#define COLOR_GLSL

// Rec. 709 luminance weights of linear RGB (ITU-R BT.709).
const vec3 REC709_LUMA = vec3(0.2126, 0.7152, 0.0722);

// Largest finite half float: what an RGBA16F texel can hold (Rust: half::f16::MAX).
const float HALF_MAX = 65504.0;

// Rec. 709 luminance of linear RGB.
float luminance(vec3 rgb) {
    return dot(rgb, REC709_LUMA);
}

#endif
