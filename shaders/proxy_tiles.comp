// Proxy tile culling (paper 002 §4.1 coverage oracle, as a compute "splat"): one invocation per
// 8x8 tile of the receiver buffer. The tile's valid receivers give a world-space box; proxy i
// is kept for the tile when its sphere of influence (centre c, radius r / support) meets the
// box. Writes 64 words per tile (bit b of word w: proxy 32 w + b), read by the SPLAT variants
// of shaders/proxy_accumulate.comp. Checked by tests/proxy.rs: splatted sums equal the
// brute-force sums over every proxy.
#version 460

layout(local_size_x = 8, local_size_y = 8) in;

// Words of a tile's proxy mask: shine::passes::proxy::TILE_WORDS.
const uint TILE_WORDS = 64u;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D recv_position;

layout(set = 0, binding = 1, std430) readonly buffer Proxies {
    vec4 p[];
} proxies;

layout(set = 0, binding = 2, std430) buffer TileMasks {
    uint m[];
} tile_masks;

// shine::passes::proxy::TilesPush
layout(push_constant) uniform Push {
    // receiver buffer size
    uvec2 extent;
    uint proxy_count;
    // min(support_shadow, support_indirect) of shine::passes::proxy::AccumulatePush
    float support;
} push;

void main() {
    uvec2 tiles = (push.extent + 7u) / 8u;
    uvec2 t = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(t, tiles))) {
        return;
    }
    vec3 lo = vec3(3.0e38);
    vec3 hi = vec3(-3.0e38);
    for (uint y = t.y * 8u; y < min(t.y * 8u + 8u, push.extent.y); ++y) {
        for (uint x = t.x * 8u; x < min(t.x * 8u + 8u, push.extent.x); ++x) {
            vec4 pos = imageLoad(recv_position, ivec2(x, y));
            if (pos.w > 0.0) {
                lo = min(lo, pos.xyz);
                hi = max(hi, pos.xyz);
            }
        }
    }
    bool any_valid = lo.x <= hi.x;
    uint base = (t.y * tiles.x + t.x) * TILE_WORDS;
    for (uint w = 0u; w < TILE_WORDS; ++w) {
        uint word = 0u;
        for (uint b = 0u; b < 32u; ++b) {
            uint i = w * 32u + b;
            if (any_valid && i < push.proxy_count) {
                vec4 sphere = proxies.p[2u * i];
                vec3 off = sphere.xyz - clamp(sphere.xyz, lo, hi);
                // |c - box| < r / support, written without dividing by a support of 0
                if (sphere.w * sphere.w > push.support * push.support * dot(off, off)) {
                    word |= 1u << b;
                }
            }
        }
        tile_masks.m[base + w] = word;
    }
}
