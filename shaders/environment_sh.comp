// `environment sh rows` and `environment sh`: a host's equirectangular environment map
// projected to SH on the GPU, the GPU twin of src/gpu_scene/environment_sh.rs (`L` per
// channel and `L̃ = L ⋆ max(0, cos)`, laid out as `EnvironmentSh::gpu_data`), for a GI
// context whose environment is an image of the host's (src/passes/environment_sh.rs). Each
// texel is integrated over its solid angle (2π/W)(π/H) sin θ; directions follow shine-scene's
// map convention: u = atan2(d.x, −d.z)/2π + ½, v = acos(d.y)/π.
//! variant rows_b3 ROWS=1 SH_BANDS=3
//! variant rows_b4 ROWS=1 SH_BANDS=4
//! variant rows_b5 ROWS=1 SH_BANDS=5
//! variant rows_b6 ROWS=1 SH_BANDS=6
//! variant total_b3 TOTAL=1 SH_BANDS=3
//! variant total_b4 TOTAL=1 SH_BANDS=4
//! variant total_b5 TOTAL=1 SH_BANDS=5
//! variant total_b6 TOTAL=1 SH_BANDS=6
#version 460
#extension GL_GOOGLE_include_directive : require
#include "sh.glsl"

#define WIDTH 64
#define VALUES (3 * SH_COEFFS)

layout(local_size_x = WIDTH) in;

#ifdef ROWS
layout(set = 0, binding = 0) uniform texture2D environment;
layout(set = 0, binding = 1) uniform sampler environment_sampler;
// Per map row: the row's integral of L·Y for r, g, b (VALUES floats).
layout(set = 0, binding = 2, std430) buffer Rows {
    float values[];
} rows;

// shine::passes::environment_sh::RowsPush
layout(push_constant) uniform Push {
    uvec2 extent;
    float intensity;
} push;

shared float partial[WIDTH];

void main() {
    uint y = gl_WorkGroupID.x;
    uint t = gl_LocalInvocationID.x;
    float w = float(push.extent.x);
    float h = float(push.extent.y);
    float theta = (float(y) + 0.5) / h * SH_PI;
    float sin_theta = sin(theta);
    float d_omega = (2.0 * SH_PI / w) * (SH_PI / h) * sin_theta;
    float acc[VALUES];
    for (int i = 0; i < VALUES; ++i) {
        acc[i] = 0.0;
    }
    for (uint x = t; x < push.extent.x; x += WIDTH) {
        float a = 2.0 * SH_PI * ((float(x) + 0.5) / w - 0.5);
        vec3 d = vec3(sin_theta * sin(a), cos(theta), -sin_theta * cos(a));
        vec3 l = texelFetch(sampler2D(environment, environment_sampler), ivec2(x, y), 0).rgb
            * push.intensity * d_omega;
        float basis[SH_COEFFS];
        sh_basis(d, basis);
        for (int k = 0; k < SH_COEFFS; ++k) {
            acc[k] += l.r * basis[k];
            acc[SH_COEFFS + k] += l.g * basis[k];
            acc[2 * SH_COEFFS + k] += l.b * basis[k];
        }
    }
    for (int i = 0; i < VALUES; ++i) {
        partial[t] = acc[i];
        barrier();
        if (t == 0) {
            float sum = 0.0;
            for (int j = 0; j < WIDTH; ++j) {
                sum += partial[j];
            }
            rows.values[y * VALUES + i] = sum;
        }
        barrier();
    }
}
#endif

#ifdef TOTAL
layout(set = 0, binding = 0, std430) readonly buffer Rows {
    float values[];
} rows;
// `L` r, g, b then `L̃` r, g, b, SH_COEFFS floats each.
layout(set = 0, binding = 1, std430) buffer Sh {
    float values[];
} sh;

// shine::passes::environment_sh::TotalPush
layout(push_constant) uniform Push {
    // Per band l: the factor of the clamped-cosine convolution, √(4π/(2l+1)) · ĉ_l.
    vec4 kernel[2];
    uint rows;
} push;

void main() {
    for (uint i = gl_LocalInvocationID.x; i < VALUES; i += WIDTH) {
        float sum = 0.0;
        for (uint y = 0; y < push.rows; ++y) {
            sum += rows.values[y * VALUES + i];
        }
        uint c = i / SH_COEFFS;
        uint k = i % SH_COEFFS;
        uint l = uint(sqrt(float(k)) + 1e-3);
        sh.values[c * SH_COEFFS + k] = sum;
        sh.values[(3 + c) * SH_COEFFS + k] = sum * push.kernel[l / 4][l % 4];
    }
}
#endif
