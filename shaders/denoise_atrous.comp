// denoise_atrous (issue 47; src/passes/denoise.rs): one iteration of the edge-stopping à-trous
// filter (SVGF, Schied et al. 2017, eq. 1-5) over a demodulated traced signal. Centre p takes
// the normalised sum over the 5×5 taps q = p + step (i, j), i, j in -2..2, of
//   w = h(i) h(j) · lobe(|q − p|², r_p) · geometry(p, q) · luminance(l_p, l_q, var_p)
// (shaders/include/denoise.glsl: the B3 kernel h, the footprint gaussian of radius r_p from
// `denoise_radius`, the plane / normal / roughness test, SVGF's luminance weight over the
// centre's variance prefiltered by a 3×3 gaussian, denoise_variance_kernel), and its
// variance Σ w² var_q / (Σ w)² (SVGF eq. 6) for the next iteration's luminance weight. The
// last iteration (push.remodulate) multiplies by the specular pass's share · ks again and
// writes the radiance with a = 0; where the footprint is sharp it writes the traced signal
// (`denoise_source`) as it came. Untraced pixels (radius −1) neither give nor take.
// Variant `diffuse` (the sky's and HVL's near field's light at receiver resolution): the
// normal tolerance DENOISE_DIFFUSE_NORMAL_TOLERANCE, no roughness test, the luminance weight
// over the larger of the two pixels' variances (symmetric: a few rays leave a skewed signal,
// mostly dark with rare bright samples; over the centre's variance alone the dark majority
// refuses the bright ones and the light loses energy), and the last iteration multiplies by
// the receiver's kd (brdf_indirect_weights), as sky_filter.comp did.
// CPU twin: shine::reference::denoise::atrous.
//! variant specular
//! variant diffuse DIFFUSE=1
#version 460
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"
#include "denoise.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba16f) readonly uniform image2D denoise_in;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D denoise_footprint;
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D gb_normal;
layout(set = 0, binding = 4, rgba8) readonly uniform image2D gb_albedo;
layout(set = 0, binding = 5, rgba8) readonly uniform image2D gb_material;
layout(set = 0, binding = 6, rgba16f) writeonly uniform image2D denoise_out;
// The signal as traced (the prep pass's input): the last iteration writes it back where the
// footprint is sharp (under DENOISE_SHARP_RADIUS), so such a pixel comes out as traced, not
// through the f16 demodulation's round trips.
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D denoise_source;

// shine::passes::denoise::AtrousPush (32 bytes).
layout(push_constant) uniform Push {
    // xyz: camera position; w: the specular pass's roughness limit (unused by `diffuse`)
    vec4 camera;
    // image size
    uvec2 extent;
    // tap spacing 2^i
    uint step;
    // 1: the last iteration, remodulated
    uint remodulate;
} push;

void main() {
    uvec2 xy = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(xy, push.extent))) {
        return;
    }
    ivec2 p = ivec2(xy);
    float radius = imageLoad(denoise_footprint, p).r;
    if (radius < 0.0) {
        imageStore(denoise_out, p, vec4(0.0));
        return;
    }
    vec4 centre = imageLoad(denoise_in, p);
    vec3 x_p = imageLoad(gb_position, p).xyz;
    vec3 n_p = normalize(imageLoad(gb_normal, p).xyz);
    vec2 material_p = imageLoad(gb_material, p).rg;
    float dist_p = length(push.camera.xyz - x_p);
    float l_p = luminance(centre.rgb);
#ifdef DIFFUSE
    // No roughness test: the diffuse light does not depend on it.
    float rough_p = 0.0;
    float tolerance = DENOISE_DIFFUSE_NORMAL_TOLERANCE;
#else
    float rough_p = material_p.x;
    float tolerance = denoise_normal_tolerance(brdf_alpha(material_p.x));
    // SVGF's variance prefilter: the luminance weight's variance is the 3×3 gaussian of the
    // traced neighbours' (the filtered variance of the next iterations stays the centre's).
    float guide_variance = 0.0;
    float guide_weight = 0.0;
    for (int j = -1; j <= 1; ++j) {
        for (int i = -1; i <= 1; ++i) {
            ivec2 c = p + ivec2(i, j);
            if (any(lessThan(c, ivec2(0))) || any(greaterThan(c, ivec2(push.extent) - 1))
                || imageLoad(denoise_footprint, c).r < 0.0) {
                continue;
            }
            float k = denoise_variance_kernel(i) * denoise_variance_kernel(j);
            guide_variance += k * imageLoad(denoise_in, c).a;
            guide_weight += k;
        }
    }
    guide_variance /= guide_weight;
#endif
    vec3 sum = vec3(0.0);
    float variance = 0.0;
    float weight_sum = 0.0;
    ivec2 last = ivec2(push.extent) - 1;
    int step = int(push.step);
    for (int j = -2; j <= 2; ++j) {
        for (int i = -2; i <= 2; ++i) {
            ivec2 offset = step * ivec2(i, j);
            ivec2 c = p + offset;
            if (any(lessThan(c, ivec2(0))) || any(greaterThan(c, last))) {
                continue;
            }
            float lobe = denoise_lobe_weight(float(offset.x * offset.x + offset.y * offset.y), radius);
            if (lobe == 0.0 || imageLoad(denoise_footprint, c).r < 0.0) {
                continue;
            }
            vec4 q = imageLoad(denoise_in, c);
#ifdef DIFFUSE
            float rough_q = 0.0;
#else
            float rough_q = imageLoad(gb_material, c).r;
#endif
            float w = denoise_kernel(i) * denoise_kernel(j) * lobe
                * denoise_geometry_weight(x_p, n_p, dist_p, rough_p, tolerance,
                    imageLoad(gb_position, c).xyz, normalize(imageLoad(gb_normal, c).xyz),
                    rough_q)
#ifdef DIFFUSE
                * denoise_luminance_weight(l_p, luminance(q.rgb), max(centre.a, q.a));
#else
                * denoise_luminance_weight(l_p, luminance(q.rgb), guide_variance);
#endif
            if (w > 0.0) {
                sum += w * q.rgb;
                variance += w * w * q.a;
                weight_sum += w;
            }
        }
    }
    vec3 value = sum / weight_sum;
    variance /= weight_sum * weight_sum;
    if (push.remodulate != 0u) {
        vec3 kd;
        vec3 ks;
        brdf_indirect_weights(imageLoad(gb_albedo, p).rgb, material_p.y,
            dot(n_p, (push.camera.xyz - x_p) / dist_p), kd, ks);
        bool sharp = radius < DENOISE_SHARP_RADIUS;
#ifdef DIFFUSE
        vec3 light = sharp ? imageLoad(denoise_source, p).rgb : value;
        imageStore(denoise_out, p, vec4(kd * light, 0.0));
#else
        float share = specular_trace_weight(material_p.x, push.camera.w);
        vec3 radiance = sharp ? imageLoad(denoise_source, p).rgb
                              : value * max(share * ks, vec3(DENOISE_MIN_WEIGHT));
        imageStore(denoise_out, p, vec4(radiance, 0.0));
#endif
    } else {
        imageStore(denoise_out, p, denoise_storable(vec4(value, variance)));
    }
}
