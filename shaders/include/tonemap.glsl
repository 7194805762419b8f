// Tonemapping and sRGB encoding: the GLSL twin of src/capture/tonemap.rs (which documents the
// operators and their sources). One function per formula; tests/composite.rs checks these
// against the Rust on the same inputs.
#ifndef SHINE_TONEMAP_GLSL
#define SHINE_TONEMAP_GLSL

// Operator ids of the `op` push constant: Tonemap::shader_id() in Rust.
#define TONEMAP_NONE 0u
#define TONEMAP_ACES 1u
#define TONEMAP_PBR_NEUTRAL 2u
#define TONEMAP_AGX 3u

// Narkowicz's ACES fit of one channel, clamped to [0, 1].
float aces_narkowicz(float x) {
    const float A = 2.51;
    const float B = 0.03;
    const float C = 2.43;
    const float D = 0.59;
    const float E = 0.14;
    return clamp((x * (A * x + B)) / (x * (C * x + D) + E), 0.0, 1.0);
}

// Khronos PBR Neutral: F90, K_s = 0.8 - F90, K_d.
const float PBR_NEUTRAL_F90 = 0.04;
const float PBR_NEUTRAL_START = 0.8 - PBR_NEUTRAL_F90;
const float PBR_NEUTRAL_DESATURATION = 0.15;

// Khronos PBR Neutral of a non-negative linear colour; the result lies in [0, 1].
vec3 pbr_neutral(vec3 color) {
    float x = min(color.r, min(color.g, color.b));
    float offset = x <= 2.0 * PBR_NEUTRAL_F90 ? x - x * x / (4.0 * PBR_NEUTRAL_F90) : PBR_NEUTRAL_F90;
    color -= vec3(offset);
    float peak = max(color.r, max(color.g, color.b));
    if (peak <= PBR_NEUTRAL_START) {
        return color;
    }
    float d = 1.0 - PBR_NEUTRAL_START;
    float new_peak = 1.0 - d * d / (peak + d - PBR_NEUTRAL_START);
    color *= new_peak / peak;
    float g = 1.0 - 1.0 / (PBR_NEUTRAL_DESATURATION * (peak - new_peak) + 1.0);
    return mix(color, vec3(new_peak), g);
}

// AgX: its log2 exposure range (EV) and its power back to linear light.
const float AGX_MIN_EV = -12.47393;
const float AGX_MAX_EV = 4.026069;
const float AGX_GAMMA = 2.2;

// The polynomial fit of AgX's default contrast sigmoid on normalised log exposure x.
float agx_contrast(float x) {
    float x2 = x * x;
    float x4 = x2 * x2;
    return 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
        - 0.00232;
}

// One channel's AgX log encoding and contrast.
float agx_encode(float c) {
    float ev = clamp(log2(max(c, 1.175494e-38)), AGX_MIN_EV, AGX_MAX_EV);
    return agx_contrast((ev - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV));
}

// AgX of a non-negative linear colour; the result lies in [0, 1]. The matrices as rows (the
// Rust twin's AGX_INSET / AGX_OUTSET), applied with dot products.
vec3 agx(vec3 color) {
    vec3 inset = vec3(dot(vec3(0.84247906, 0.0784336, 0.079223745), color),
                      dot(vec3(0.042328242, 0.8784686, 0.07916613), color),
                      dot(vec3(0.042375655, 0.0784336, 0.879143), color));
    vec3 curved = vec3(agx_encode(inset.r), agx_encode(inset.g), agx_encode(inset.b));
    vec3 display = max(vec3(dot(vec3(1.196879, -0.09802088, -0.09902974), curved),
                            dot(vec3(-0.05289685, 1.1519031, -0.09896118), curved),
                            dot(vec3(-0.052971635, -0.09804345, 1.1510737), curved)),
                       vec3(0.0));
    return min(pow(display, vec3(AGX_GAMMA)), vec3(1.0));
}

// The sRGB OETF (linear [0, 1] -> encoded [0, 1]), piecewise as IEC 61966-2-1.
float srgb_oetf(float linear) {
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
}

// Tonemaps exposed linear radiance with operator `op`: linear, in [0, 1].
vec3 tonemap(uint op, vec3 exposed) {
    vec3 c = max(exposed, vec3(0.0));
    if (op == TONEMAP_ACES) {
        return vec3(aces_narkowicz(c.r), aces_narkowicz(c.g), aces_narkowicz(c.b));
    }
    if (op == TONEMAP_PBR_NEUTRAL) {
        return pbr_neutral(c);
    }
    if (op == TONEMAP_AGX) {
        return agx(c);
    }
    return min(c, vec3(1.0));
}

// Quantizes an encoded [0, 1] value to the nearest 8-bit level (halves up), returned as
// level / 255 so that storing it into a UNORM8 image is exact whatever the device's rounding.
float quantize_unorm8(float encoded) {
    return floor(clamp(encoded, 0.0, 1.0) * 255.0 + 0.5) / 255.0;
}

// The LDR value of exposed radiance: tonemapped, sRGB-encoded, quantized; alpha opaque.
vec4 encode_ldr(uint op, vec3 exposed) {
    vec3 mapped = tonemap(op, exposed);
    return vec4(quantize_unorm8(srgb_oetf(mapped.r)), quantize_unorm8(srgb_oetf(mapped.g)),
                quantize_unorm8(srgb_oetf(mapped.b)), 1.0);
}

#endif
