// specular_budget (issue 47, item 2; src/passes/specular.rs): each 8×8 tile's share of the
// frame's specular rays. Per pixel, the claim denoise_ray_weight (trace share × the lobe's
// width plus a floor; 0 where the specular pass traces nothing) and whether it is traced;
// thread 0 sums the tile's 64 in order (a fixed order: the frame's total is the same on every
// run). Writes `budget_tiles`, per tile (claims, traced pixels), row-major tiles;
// specular_budget_total.comp sums them.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"
#include "denoise.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D gb_normal;
layout(set = 0, binding = 2, rgba8) readonly uniform image2D gb_material;
layout(set = 0, binding = 3, std430) buffer BudgetTiles {
    vec2 t[];
} budget_tiles;

// shine::passes::specular::BudgetPush (32 bytes).
layout(push_constant) uniform Push {
    // xyz: camera position; w: the roughness limit
    vec4 camera;
    // image size
    uvec2 extent;
    // tiles per row
    uint tiles_x;
    uint pad;
} push;

shared vec2 claims[64];

void main() {
    uvec2 xy = gl_GlobalInvocationID.xy;
    vec2 claim = vec2(0.0);
    if (all(lessThan(xy, push.extent))) {
        ivec2 p = ivec2(xy);
        vec4 position = imageLoad(gb_position, p);
        vec2 roughness_metallic = imageLoad(gb_material, p).rg;
        float share = specular_trace_weight(roughness_metallic.x, push.camera.w);
        vec3 n = imageLoad(gb_normal, p).xyz;
        bool traced = position.w != 0.0 && share > 0.0 && dot(n, n) > 0.0
            && dot(normalize(n), push.camera.xyz - position.xyz) > 0.0;
        if (traced) {
            claim = vec2(denoise_ray_weight(brdf_alpha(roughness_metallic.x), share), 1.0);
        }
    }
    claims[gl_LocalInvocationIndex] = claim;
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        vec2 sum = vec2(0.0);
        for (uint i = 0u; i < 64u; ++i) {
            sum += claims[i];
        }
        budget_tiles.t[gl_WorkGroupID.y * push.tiles_x + gl_WorkGroupID.x] = sum;
    }
}
