// denoise_prep (issue 47; src/passes/denoise.rs): a traced signal made ready for the à-trous
// filter (denoise_atrous.comp). Variant `specular`: the specular pass's one-sample radiance
// (full resolution); variant `diffuse`: the sky's or HVL's near field's demodulated light
// (receiver resolution). Per traced pixel p:
// - demodulated: the specular divided by share · ks (specular_trace_weight times the Schlick
//   Fresnel at n·v, brdf_indirect_weights), so the albedo's colour and texture and the trace
//   share stay out of the filter and come back in its last iteration; the diffuse light comes
//   demodulated already (light / π, kd comes back in the last iteration);
// - the firefly clamp (push.clamp): the luminance l_p of the demodulated value is held to
//   DENOISE_FIREFLY_RATIO times the largest of its 3×3 neighbours on the same surface
//   (geometry weight ≥ DENOISE_MATCH with the neighbour's roughness taken at
//   denoise_clamp_roughness: a smoother neighbour counts, whatever the roughness test says),
//   so a lone bright pixel no neighbour confirms is cut to what its neighbourhood holds, a
//   tile edge's pixel of its own roughness too (the energy it removes: docs/quality.md,
//   frames with `denoise.clamp` on and off); a sharp footprint (under DENOISE_SHARP_RADIUS) is
//   never clamped: a mirror's rays agree, its lone bright pixel is a highlight;
// - the luminance variance over that 3×3 (the clamped centre and its matching neighbours,
//   roughness tested, equal weights), SVGF's guide of the luminance weight;
// - the footprint radius in pixels: specular, denoise_radius from its roughness and the
//   parallax d / (z + d) the specular pass stores in alpha, averaged over the same neighbours;
//   diffuse (shine::passes::denoise::Footprint, which says why), a stated radius in pixels
//   (the sky), or push.camera.w times the rays' mean hit distance the light holds in alpha,
//   averaged so, through denoise_world_radius (HVL's near field); with the normal tolerance
//   DENOISE_DIFFUSE_NORMAL_TOLERANCE and no roughness test.
// The firefly clamp is the specular's (src/passes/denoise.rs passes clamp = 0 for the diffuse
// signals: a few rays leave neighbours at 0, and a lone ray's real light would be cut).
// Writes `denoise_signal` (rgb demodulated, a variance) and `denoise_footprint` (r: radius in
// pixels; -1 where nothing is traced). CPU twin: shine::reference::denoise::prep.
//! variant specular
//! variant diffuse DIFFUSE=1
#version 460
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"
#include "denoise.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

#ifdef DIFFUSE
// The demodulated light (rgb), at the resolution of the guide images.
layout(set = 0, binding = 0, rgba16f) readonly uniform image2D light;
#else
layout(set = 0, binding = 0, rgba16f) readonly uniform image2D specular;
layout(set = 0, binding = 3, rgba8) readonly uniform image2D gb_albedo;
layout(set = 0, binding = 4, rgba8) readonly uniform image2D gb_material;
#endif
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D gb_normal;
layout(set = 0, binding = 5, rgba16f) writeonly uniform image2D denoise_signal;
layout(set = 0, binding = 6, rgba16f) writeonly uniform image2D denoise_footprint;

// shine::passes::denoise::PrepPush (32 bytes).
layout(push_constant) uniform Push {
    // xyz: camera position; w: `specular`, the specular pass's roughness limit; `diffuse`, the
    // footprint's radius over the light's alpha, its rays' mean hit distance (0:
    // push.footprint is the radius in pixels)
    vec4 camera;
    // image size
    uvec2 extent;
    // `specular`, or `diffuse` from hit distances: the angle one pixel subtends at the eye
    // (perspective), radians; else the footprint radius in pixels
    float footprint;
    // 1: the firefly clamp on
    uint clamp_fireflies;
} push;

// What one pixel holds for the filter: demodulated radiance, parallax, geometry; traced false
// where the specular pass left it out.
struct Texel {
    bool traced;
    vec3 demodulated;
    float parallax;
    vec3 position;
    vec3 normal;
    float dist;
    float roughness;
};

Texel texel(ivec2 c) {
    Texel t;
    vec4 position = imageLoad(gb_position, c);
    vec3 n = imageLoad(gb_normal, c).xyz;
#ifdef DIFFUSE
    t.position = position.xyz;
    t.roughness = 0.0;
    t.dist = length(push.camera.xyz - position.xyz);
    t.traced = position.w > 0.0 && dot(n, n) > 0.0 && t.dist > 0.0;
    if (t.traced) {
        t.normal = normalize(n);
        vec4 l = imageLoad(light, c);
        t.demodulated = l.rgb;
        t.parallax = l.a;
    }
    return t;
#else
    vec2 roughness_metallic = imageLoad(gb_material, c).rg;
    t.position = position.xyz;
    t.roughness = roughness_metallic.x;
    t.dist = length(push.camera.xyz - position.xyz);
    float share = specular_trace_weight(roughness_metallic.x, push.camera.w);
    t.traced = position.w != 0.0 && share > 0.0 && dot(n, n) > 0.0 && t.dist > 0.0;
    if (!t.traced) {
        return t;
    }
    t.normal = normalize(n);
    float nv = dot(t.normal, (push.camera.xyz - position.xyz) / t.dist);
    t.traced = nv > 0.0;
    vec3 kd;
    vec3 ks;
    brdf_indirect_weights(imageLoad(gb_albedo, c).rgb, roughness_metallic.y, nv, kd, ks);
    vec4 s = imageLoad(specular, c);
    t.demodulated = s.rgb / max(share * ks, vec3(DENOISE_MIN_WEIGHT));
    t.parallax = s.a;
    return t;
#endif
}

void main() {
    uvec2 xy = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(xy, push.extent))) {
        return;
    }
    ivec2 p = ivec2(xy);
    Texel centre = texel(p);
    if (!centre.traced) {
        imageStore(denoise_signal, p, vec4(0.0));
        imageStore(denoise_footprint, p, vec4(-1.0));
        return;
    }
    ivec2 last = ivec2(push.extent) - 1;
#ifdef DIFFUSE
    float tolerance = DENOISE_DIFFUSE_NORMAL_TOLERANCE;
#else
    float tolerance = denoise_normal_tolerance(brdf_alpha(centre.roughness));
#endif
    float bound = -1.0;
    float sum = 0.0;
    float sum2 = 0.0;
    float parallax = centre.parallax;
    float count = 1.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 c = p + ivec2(dx, dy);
            if ((dx == 0 && dy == 0) || any(lessThan(c, ivec2(0))) || any(greaterThan(c, last))) {
                continue;
            }
            Texel q = texel(c);
            if (!q.traced) {
                continue;
            }
            float l = luminance(q.demodulated);
            // The clamp's neighbours: the same surface, a lobe no wider than the centre's.
            if (denoise_geometry_weight(centre.position, centre.normal, centre.dist,
                    centre.roughness, tolerance, q.position, q.normal,
                    denoise_clamp_roughness(centre.roughness, q.roughness)) >= DENOISE_MATCH) {
                bound = max(bound, l);
            }
            if (denoise_geometry_weight(centre.position, centre.normal, centre.dist,
                    centre.roughness, tolerance, q.position, q.normal, q.roughness) < DENOISE_MATCH) {
                continue;
            }
            sum += l;
            sum2 += l * l;
            parallax += q.parallax;
            count += 1.0;
        }
    }
#ifdef DIFFUSE
    float radius = push.camera.w > 0.0
        ? denoise_world_radius(push.camera.w * parallax / count, centre.dist, push.footprint)
        : push.footprint;
#else
    float radius = denoise_radius(brdf_alpha(centre.roughness), parallax / count,
        push.footprint);
#endif
    vec3 value = centre.demodulated;
    float l_p = luminance(value);
    bound *= DENOISE_FIREFLY_RATIO;
    if (push.clamp_fireflies != 0u && radius >= DENOISE_SHARP_RADIUS && bound >= 0.0 && l_p > bound) {
        value *= bound / l_p;
        l_p = bound;
    }
    sum += l_p;
    sum2 += l_p * l_p;
    float mean = sum / count;
    float variance = max(sum2 / count - mean * mean, 0.0);
    imageStore(denoise_signal, p, denoise_storable(vec4(value, variance)));
    imageStore(denoise_footprint, p, vec4(radius, 0.0, 0.0, 0.0));
}
