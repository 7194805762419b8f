// AAF screen-space filter (paper 004 §5, src/passes/aaf/): a separable filter of the per-pixel
// mean incident radiance, its diffuse and specular parts apart (aaf_sample.comp), the diffuse
// part as an irradiance vector V (aaf.glsl) evaluated at each pixel's shading normal, with gaussian
// weights of standard deviation beta (world units, the aaf_beta pass) of the CENTRE pixel, over
// world-space distances between the pixels' positions: per pass and part, a weighted
// least-squares polynomial fit of degree `degree` along the axis (AafFit in aaf.glsl; degree 0
// is the paper's normalised gaussian). The x pass weights every pixel's means alike; above
// degree 0, the y pass weights each row by its x fit's precision (the inverse of its noise
// variance: a row fitted from few neighbours counts less). A neighbour counts only when its
// shading normal is within the normal threshold of the centre's (paper 004: 10 degrees) and it
// lies within `plane_tolerance` pixel footprints of the centre's geometric tangent plane (a
// normal map's tilt would push coplanar neighbours off a shading plane), so no light leaks
// across surfaces.
// The diffuse part takes every such neighbour whose kd carries light (the diffuse mean is the
// irradiance over pi whatever the material), testing geometric normals (a normal map's detail
// is in V . n, not in which neighbours count); the specular part only neighbours within the
// threshold of the shading normal whose roughness is within `roughness_tolerance` of the
// centre's (the mean of a lobe depends on its width). With `irradiance_vector` = 0 the diffuse
// part is the paper's scalar mean (V = mean n of the centre) with shading normals tested.
// `x` filters rows into `filtered`; `y` filters columns and weights the parts by the receiver's
// kd and ks (1 - specular_trace_weight) (brdf_indirect_weights) into the indirect image. With
// `enabled` = 0 the means pass through unfiltered (uniform Monte Carlo).
// CPU twin: shine::reference::aaf::filter_cpu.
//! variant x AAF_X=1
//! variant y AAF_Y=1
#version 460
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"
#include "aaf.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D gb_normal;
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D gb_geometric_normal;
layout(set = 0, binding = 5, rgba8) readonly uniform image2D gb_material;
layout(set = 0, binding = 2, std430) readonly buffer Filter {
    vec2 f[];
} filter_widths;
#ifdef AAF_X
// The sampling passes' sums (AAF_SUMS_STRIDE vec4 per pixel, aaf_sample.comp).
layout(set = 0, binding = 3, std430) readonly buffer Sums {
    vec4 s[];
} sums;
// AAF_ROWS_STRIDE vec4 per pixel: the filtered irradiance vector's x, y, z columns (rgb; w of
// the first two: the diffuse and the specular fit's precision), then the filtered specular mean
// and 1 where the diffuse part holds light.
layout(set = 0, binding = 4, std430) buffer Filtered {
    vec4 m[];
} filtered;
#else
layout(set = 0, binding = 3, std430) readonly buffer Filtered {
    vec4 m[];
} filtered;
layout(set = 0, binding = 4, rgba8) readonly uniform image2D gb_albedo;
layout(set = 0, binding = 6, rgba16f) writeonly uniform image2D indirect;
#endif

// shine::passes::aaf::FilterPush (64 bytes).
layout(push_constant) uniform Push {
    // xyz: camera position; w: cos of the normal threshold.
    vec4 camera;
    uvec2 extent;
    // d = linear depth * footprint.x + footprint.y.
    vec2 footprint;
    // Neighbours at most this far from the centre's tangent plane, in pixel footprints.
    float plane_tolerance;
    // Largest filter radius in pixels.
    uint max_radius;
    // 1: filter; 0: pass the mean through.
    uint enabled;
    // The specular pass's roughness limit (0: none).
    float specular_limit;
    // Degree of the local polynomial fit (0: the paper's gaussian).
    uint degree;
    // Largest roughness difference between a pixel and the neighbours its specular part takes.
    float roughness_tolerance;
    // 1: the diffuse part as an irradiance vector, geometric normals tested; 0: the paper's
    // scalar mean, shading normals tested.
    uint irradiance_vector;
    uint pad;
} push;

// Pixel q's diffuse part as an irradiance vector (columns x, y, z), its specular mean and
// whether the diffuse part holds light; nq is q's shading normal and n the centre's. Without
// irradiance_vector, the diffuse part is q's scalar mean along n (V = mean n).
struct Means {
    mat3 diffuse;
    vec3 specular;
    bool lit;
    // The precisions of the diffuse and specular parts (LocalFit::precision): 1 for a pixel's
    // sampled means, the first pass's fit for a row.
    float diffuse_precision;
    float specular_precision;
};

Means means_at(uint q, vec3 nq, vec3 n) {
#ifdef AAF_X
    uint k = AAF_SUMS_STRIDE * q;
    vec4 s = sums.s[k];
    vec4 specular = sums.s[k + 1u];
    float inverse = s.w > 0.0 ? 1.0 / s.w : 0.0;
    vec3 mean = (s.rgb - specular.rgb) * inverse;
    mat3 diffuse = push.irradiance_vector != 0u
        ? outerProduct(mean, nq)
            + AAF_TANGENT_SCALE * inverse * mat3(sums.s[k + 2u].rgb, sums.s[k + 3u].rgb, sums.s[k + 4u].rgb)
        : outerProduct(mean, n);
    return Means(diffuse, specular.rgb * inverse, specular.w > 0.0, 1.0, 1.0);
#else
    uint k = AAF_ROWS_STRIDE * q;
    mat3 diffuse = mat3(filtered.m[k].rgb, filtered.m[k + 1u].rgb, filtered.m[k + 2u].rgb);
    if (push.irradiance_vector == 0u) {
        diffuse = outerProduct(diffuse * nq, n);
    }
    vec4 specular = filtered.m[k + 3u];
    bool weighted = push.degree > 0u;
    return Means(diffuse, specular.rgb, specular.w > 0.0, weighted ? filtered.m[k].w : 1.0,
        weighted ? filtered.m[k + 1u].w : 1.0);
#endif
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(pixel, push.extent))) {
        return;
    }
    uint p = pixel.y * push.extent.x + pixel.x;
    ivec2 ixy = ivec2(pixel);
    vec4 position = imageLoad(gb_position, ixy);
    float beta = filter_widths.f[p].x;
    vec3 n = normalize(imageLoad(gb_normal, ixy).xyz);
    Means result = means_at(p, n, n);
    vec3 ng = normalize(imageLoad(gb_geometric_normal, ixy).xyz);
    vec2 roughness_metallic = imageLoad(gb_material, ixy).rg;
    if (push.enabled != 0u && position.w > 0.0 && beta > 0.0) {
        float d = position.w * push.footprint.x + push.footprint.y;
        uint radius = min(push.max_radius, uint(ceil(2.0 * beta / d)));
#ifdef AAF_X
        ivec2 axis = ivec2(1, 0);
        int limit = int(push.extent.x);
        int coordinate = ixy.x;
#else
        ivec2 axis = ivec2(0, 1);
        int limit = int(push.extent.y);
        int coordinate = ixy.y;
#endif
        AafFit diffuse = aaf_fit_new();
        AafFit specular = aaf_fit_new();
        for (int k = -int(radius); k <= int(radius); ++k) {
            int c = coordinate + k;
            if (c < 0 || c >= limit) {
                continue;
            }
            ivec2 q = ixy + axis * k;
            vec4 xq = imageLoad(gb_position, q);
            if (xq.w == 0.0) {
                continue;
            }
            vec3 offset = xq.xyz - position.xyz;
            if (abs(dot(ng, offset)) > push.plane_tolerance * d) {
                continue;
            }
            vec3 nq = normalize(imageLoad(gb_normal, q).xyz);
            bool shading_close = dot(n, nq) >= push.camera.w;
            bool diffuse_close = push.irradiance_vector != 0u
                ? dot(ng, normalize(imageLoad(gb_geometric_normal, q).xyz)) >= push.camera.w
                : shading_close;
            bool specular_close = shading_close
                && abs(imageLoad(gb_material, q).r - roughness_metallic.x) <= push.roughness_tolerance;
            if (!diffuse_close && !specular_close) {
                continue;
            }
            float u = sign(float(k)) * length(offset) / beta;
            Means m = means_at(uint(q.y) * push.extent.x + uint(q.x), nq, n);
            if (diffuse_close && m.lit) {
                aaf_fit_add(diffuse, u, m.diffuse, m.diffuse_precision);
            }
            if (specular_close) {
                mat3 y = mat3(m.specular, vec3(0.0), vec3(0.0));
                aaf_fit_add(specular, u, y, m.specular_precision);
            }
        }
        uint degree = push.degree;
#ifdef AAF_X
        // The columns' pass weights each row by these; its own are not needed.
        result.diffuse_precision = aaf_fit_precision(diffuse, degree, result.diffuse_precision);
        result.specular_precision = aaf_fit_precision(specular, degree, result.specular_precision);
#endif
        result.diffuse = aaf_fit_value(diffuse, degree, result.diffuse);
        mat3 specular_own = mat3(result.specular, vec3(0.0), vec3(0.0));
        result.specular = aaf_fit_value(specular, degree, specular_own)[0];
        result.lit = result.lit || diffuse.s0 > 0.0;
    }
#ifdef AAF_X
    filtered.m[AAF_ROWS_STRIDE * p] = vec4(result.diffuse[0], result.diffuse_precision);
    filtered.m[AAF_ROWS_STRIDE * p + 1u] = vec4(result.diffuse[1], result.specular_precision);
    filtered.m[AAF_ROWS_STRIDE * p + 2u] = vec4(result.diffuse[2], 0.0);
    filtered.m[AAF_ROWS_STRIDE * p + 3u] = vec4(result.specular, result.lit ? 1.0 : 0.0);
#else
    vec3 out_radiance = vec3(0.0);
    if (position.w > 0.0) {
        vec3 albedo = imageLoad(gb_albedo, ixy).rgb;
        vec3 v = normalize(push.camera.xyz - position.xyz);
        vec3 kd;
        vec3 ks;
        brdf_indirect_weights(albedo, roughness_metallic.y, dot(n, v), kd, ks);
        float traced = specular_trace_weight(roughness_metallic.x, push.specular_limit);
        out_radiance = kd * max(result.diffuse * n, vec3(0.0)) + ks * (1.0 - traced) * max(result.specular, vec3(0.0));
    }
    imageStore(indirect, ixy, vec4(out_radiance, 0.0));
#endif
}
