// Tonemapping and sRGB encoding: the GLSL twin of src/capture/tonemap.rs (which documents the
// operators and their sources). One function per formula; tests/composite.rs checks these
// against the Rust on the same inputs.
#ifndef SHINE_TONEMAP_GLSL
#define SHINE_TONEMAP_GLSL

// Operator ids of the `op` push constant: Tonemap::shader_id() in Rust.
#define TONEMAP_NONE 0u
#define TONEMAP_ACES 1u
#define TONEMAP_PBR_NEUTRAL 2u

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
