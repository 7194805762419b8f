// AAF sampling (paper 004 §5, src/passes/aaf/): Monte-Carlo estimate of the indirect light
// leaving every G-buffer pixel towards the camera, with directions cosine-weighted about the
// shading normal, diffuse and glossy parts apart (paper 004 §6): a sample carrying radiance L
// from direction l adds pi L f_d(l, v) / kd to the diffuse sum (aaf_diffuse_share: one ratio
// for the three channels) and pi f_s(l, v) L / ks to the specular one, f_d + f_s the
// receiver's metallic-roughness BRDF and kd, ks its demodulation weights
// (brdf_indirect_weights; for a Lambertian receiver the diffuse mean is the irradiance over
// pi, the quantity paper 004 filters). The directions of a pixel's samples are the points of
// a digitally shifted (0, 2)-sequence (sobol_02): the first 2^k of them, and every aligned
// block of 2^k after, are stratified (the paper stratifies both passes). Each sample
// traces a ray through the BVH; where it hits, the radiance leaving the hit towards the pixel is
// next-event estimation to the punctual lights (path.glsl), continued for `bounces` - 1 further
// BRDF-sampled vertices. Misses, emission and the environment add nothing (the raster GI
// convention: punctual lights only). Each hit's BRDF is evaluated no sharper than
// config.w's roughness (path regularisation: a point light's highlight on a mirror-like hit
// is a caustic no gathering ray samples).
//
// `first`: the first `samples` samples; writes the sums and the nearest/farthest hit distances (z_min, z_max; 0, 0
// without a hit). `second`: the pixel's remaining samples up to the count of the aaf_beta pass
// (eq. 21), added to the first pass's sums.
//! variant first AAF_FIRST=1
//! variant second AAF_SECOND=1
#version 460
#extension GL_GOOGLE_include_directive : require
#define SURFACE_SAMPLE(tex, uvw) textureLod(sampler2DArray(tex, texture_sampler), uvw, 0.0)
#include "surface.glsl"
#include "brdf.glsl"
#define TRACE_NODES_BINDING 7
#define TRACE_TRIANGLES_BINDING 8
#define TRACE_TOP_BINDING 17
#define TRACE_INSTANCES_BINDING 18
#include "trace.glsl"
#include "aaf.glsl"
#include "amortise.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// shine::passes::aaf::SamplePush (48 bytes).
layout(push_constant) uniform Push {
    // x: width, y: height, z: light count, w: seed.
    uvec4 frame;
    // x: bounces B, y: samples of the first pass, z: the pixels sampled (0: every pixel;
    // 1 + k: the pixel at (k & 1, k >> 1) of every 2x2 cell; AMORTISE_REGATHER_SLICE: those
    // `marks` marks; src/passes/amortise.rs), w: the bits of the least roughness at the hits
    // (AafParams::hit_roughness_min, path regularisation).
    uvec4 config;
    // xyz: camera position, w: padding.
    vec4 camera;
} push;

#define PATH_LIGHT_COUNT push.frame.z
#define PATH_FLAGS 0u
#include "path.glsl"

layout(set = 0, binding = 9, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 10, rgba16f) readonly uniform image2D gb_normal;
layout(set = 0, binding = 11, rgba16f) readonly uniform image2D gb_geometric_normal;
layout(set = 0, binding = 15, rgba8) readonly uniform image2D gb_albedo;
layout(set = 0, binding = 16, rgba8) readonly uniform image2D gb_material;
// AAF_SUMS_STRIDE vec4 per pixel: the diffuse plus the specular sum (rgb: what the amortised
// change test compares, RecordSignal::MeanRgb) and the samples taken (a), then the
// specular sum (rgb) and 1 where kd carries light (a; AAF_WEIGHT_MIN), then the sums of the
// diffuse samples times the x, y and z of their direction's part tangent to the shading normal
// (rgb each; the irradiance vector's tangent part, aaf.glsl).
layout(set = 0, binding = 12, std430) buffer Sums {
    vec4 s[];
} sums;
// Slice AMORTISE_REGATHER_SLICE: the pixels to sample, alpha -1 (aaf_reproject); not read by
// the other slices.
layout(set = 0, binding = 19, rgba16f) readonly uniform image2D marks;
#ifdef AAF_FIRST
// x: z_min, y: z_max of the pixel's hits.
layout(set = 0, binding = 13, std430) buffer Depths {
    vec2 z[];
} depths;
#else
// The first pass's sums, laid out as `sums`.
layout(set = 0, binding = 13, std430) readonly buffer FirstSums {
    vec4 s[];
} first_sums;
// x: beta (world units), y: samples per pixel (eq. 21, clamped).
layout(set = 0, binding = 14, std430) readonly buffer Filter {
    vec2 f[];
} filter_widths;
#endif

// Radiance arriving at the receiver along `dir` from the hit `hit`: NEE at the hit, then
// bounces - 1 more BRDF-sampled vertices (as path_trace.comp's indirect paths).
vec3 incident(vec3 dir, TraceHit hit, uint bounces) {
    vec3 radiance = vec3(0.0);
    vec3 throughput = vec3(1.0);
    for (uint vertex = 1u; ; ++vertex) {
        Vertex x = shade(hit, dir);
        x.s.roughness = max(x.s.roughness, uintBitsToFloat(push.config.w));
        vec3 v = -dir;
        radiance += throughput * punctual_lights(x, v);
        if (vertex >= bounces) {
            break;
        }
        vec3 xi = vec3(rand(), rand(), rand());
        vec3 n = x.s.normal;
        float p_specular = brdf_specular_probability(x.s.base_color, x.s.metallic);
        vec3 l = brdf_sample(n, v, p_specular, x.s.roughness, xi);
        float pdf = brdf_pdf(n, l, v, p_specular, x.s.roughness);
        vec3 weight = pdf > 0.0 ? brdf(x, l, v) * max(dot(n, l), 0.0) / pdf : vec3(0.0);
        if (dot(n, l) <= 0.0 || dot(x.geometric_normal, l) <= 0.0 || all(equal(weight, vec3(0.0)))) {
            break;
        }
        throughput *= weight;
        dir = l;
        if (!trace_closest(trace_offset(x.position, x.geometric_normal), dir, 0.0, PT_FAR, hit)) {
            break;
        }
    }
    return radiance;
}

void main() {
    uvec2 pixel = uvec2(amortise_pixel(gl_GlobalInvocationID.xy, push.config.z));
    uvec2 extent = push.frame.xy;
    if (any(greaterThanEqual(pixel, extent))) {
        return;
    }
    if (push.config.z == AMORTISE_REGATHER_SLICE && imageLoad(marks, ivec2(pixel)).a >= 0.0) {
        return;
    }
    uint p = pixel.y * extent.x + pixel.x;
    uint record = AAF_SUMS_STRIDE * p;
    ivec2 ixy = ivec2(pixel);
    vec4 position = imageLoad(gb_position, ixy);
#ifdef AAF_FIRST
    uint begin = 0u;
    uint end = push.config.y;
    vec4 sum = vec4(0.0);
    vec3 specular_sum = vec3(0.0);
    mat3 tangent_sum = mat3(0.0);
#else
    vec3 specular_sum = first_sums.s[record + 1u].rgb;
    vec4 sum = first_sums.s[record] - vec4(specular_sum, 0.0);
    mat3 tangent_sum = mat3(first_sums.s[record + 2u].rgb, first_sums.s[record + 3u].rgb, first_sums.s[record + 4u].rgb);
    uint begin = uint(sum.w);
    uint end = max(begin, uint(filter_widths.f[p].y));
#endif
    if (position.w == 0.0) {
        for (uint k = 0u; k < AAF_SUMS_STRIDE; ++k) {
            sums.s[record + k] = vec4(0.0);
        }
#ifdef AAF_FIRST
        depths.z[p] = vec2(0.0);
#endif
        return;
    }
    vec3 n = normalize(imageLoad(gb_normal, ixy).xyz);
    vec3 ng = normalize(imageLoad(gb_geometric_normal, ixy).xyz);
    vec3 origin = trace_offset(position.xyz, ng);
    vec3 v = normalize(push.camera.xyz - position.xyz);
    vec3 albedo = imageLoad(gb_albedo, ixy).rgb;
    vec2 roughness_metallic = imageLoad(gb_material, ixy).rg;
    vec3 kd;
    vec3 ks;
    brdf_indirect_weights(albedo, roughness_metallic.y, dot(n, v), kd, ks);
    uint pixel_seed = pcg(pcg(pixel.x ^ pcg(push.frame.w ^ 0x9e3779b9u)) + pixel.y);
    uvec2 shift = uvec2(pixel_seed, pcg(pixel_seed));
    float z_min = PT_FAR;
    float z_max = 0.0;
    for (uint s = begin; s < end; ++s) {
        vec2 xi = sobol_02(s, shift);
        rng_state = pcg(pcg(pcg(pixel.x ^ pcg(push.frame.w)) + pixel.y) + s);
        vec3 l = sample_cosine(n, xi);
        sum.w += 1.0;
        TraceHit hit;
        if (dot(ng, l) <= 0.0 || !trace_closest(origin, l, 0.0, PT_FAR, hit)) {
            continue;
        }
        z_min = min(z_min, hit.t);
        z_max = max(z_max, hit.t);
        vec3 f_d;
        vec3 f_s;
        brdf_metallic_roughness_parts(n, l, v, albedo, roughness_metallic.y, roughness_metallic.x, f_d, f_s);
        vec3 radiance = incident(l, hit, push.config.x) * BRDF_PI;
        vec3 diffuse = radiance * aaf_diffuse_share(f_d, kd);
        vec3 specular = radiance * f_s / max(ks, vec3(AAF_WEIGHT_MIN));
        if (!any(isnan(diffuse)) && !any(isinf(diffuse)) && !any(isnan(specular)) && !any(isinf(specular))) {
            sum.rgb += diffuse;
            specular_sum += specular;
            vec3 t = l - n * dot(n, l);
            tangent_sum += mat3(diffuse * t.x, diffuse * t.y, diffuse * t.z);
        }
    }
    sums.s[record] = vec4(sum.rgb + specular_sum, sum.w);
    sums.s[record + 1u] = vec4(specular_sum, aaf_carries_light(kd) ? 1.0 : 0.0);
    for (uint k = 0u; k < 3u; ++k) {
        sums.s[record + 2u + k] = vec4(tangent_sum[k], 0.0);
    }
#ifdef AAF_FIRST
    depths.z[p] = z_max > 0.0 ? vec2(z_min, z_max) : vec2(0.0);
#endif
}
