// Proxy accumulation (paper 002 §3-5): at every receiver, the summed log-occlusion SH vector of
// the proxy spheres (eq. 4) and the summed indirect shading I_i . H(N_p) with the summed solid
// angle omega_p (eq. 12-15), in one compute pass (docs/frame.md, "Proxy GI", says why compute and not raster).
//
// SPLAT: image-space splatting as a tiled compute pass. shaders/proxy_tiles.comp culled, per
//   8x8 tile of the receiver buffer, every proxy whose sphere of influence (radius r / support,
//   see below) misses the world-space box of the tile's receivers; each receiver tests the
//   remaining proxies, the tile's neighbour list (paper 001), for being inside their sphere
//   of influence (the paper's depth test against the splatted sphere) and accumulates them.
//   No barrier: lavapipe compiles compute shaders with barriers as coroutines, which took
//   minutes for this shader.
// BRUTE: every proxy at every receiver, no culling, no influence test (tests compare SPLAT to
//   it: the result must be equal).
// PRODUCT: every proxy at every receiver with the unclamped tables, and the occlusion as the
//   exact chain of SH products O_1 * O_2 * ... (eq. 4 without logs); `sums` then holds O_p, not
//   its log.
//
// Per proxy i (centre c, radius r) at receiver p with unit normal n:
//   (c', r') = self-shadow substitute (sh_proxy_self_shadow); skipped when r' = 0
//   alpha = min(r' / |c' - p|, 1), d = (c' - p) / |c' - p|                        eq. 1
//   log-occlusion += rot(O_log(alpha), d)                                          eq. 4, 8
//   V_i = rot(V(alpha), d) (3 bands), kappa_i = rot(D(alpha), d) . L~  (rgb)      eq. 14, 15
//   indirect += (albedo_i / pi) kappa_i (V_i . H(n)),  omega += (V_i)_0 sqrt(4 pi)  eq. 12
// O_log and V are rows of shine_sh::sphere_blocker::AlphaTable, smoothly clamped (§4.1).
// A table is exactly 0 for alpha <= its support, so a proxy with r <= support |c - p| adds
// nothing (the substitute sphere lies inside the original one, so its alpha is not larger):
// the sphere of influence has radius r / support. CPU twin: shine::reference::proxy::accumulate_cpu.
//! variant splat_b3 SPLAT=1 SH_BANDS=3
//! variant splat_b4 SPLAT=1 SH_BANDS=4
//! variant splat_b5 SPLAT=1 SH_BANDS=5
//! variant splat_b6 SPLAT=1 SH_BANDS=6
//! variant brute_b3 BRUTE=1 SH_BANDS=3
//! variant brute_b4 BRUTE=1 SH_BANDS=4
//! variant brute_b5 BRUTE=1 SH_BANDS=5
//! variant brute_b6 BRUTE=1 SH_BANDS=6
//! variant product_b3 PRODUCT=1 SH_BANDS=3
//! variant product_b4 PRODUCT=1 SH_BANDS=4
//! variant product_b5 PRODUCT=1 SH_BANDS=5
//! variant product_b6 PRODUCT=1 SH_BANDS=6
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define SH_LOOP_ATTRIBUTES
#define PROXY_TABLES_BINDING 3
#include "proxy_tables.glsl"
#include "sh.glsl"
#include "amortise.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D recv_normal;

layout(set = 0, binding = 2, std430) readonly buffer Proxies {
    vec4 p[];
} proxies;

layout(set = 0, binding = 4, std430) readonly buffer Environment {
    float e[];
} environment;

layout(set = 0, binding = 5, std430) buffer Sums {
    float s[];
} sums;

// Slice AMORTISE_REGATHER_SLICE: the receivers to accumulate, alpha -1 (proxy_regather_mask);
// not read by the other slices.
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D marks;

// shine::passes::proxy::AccumulatePush
layout(push_constant) uniform Push {
    uvec2 extent;
    uint proxy_count;
    uint table_entries;
    // largest alpha at which the shadow / indirect table is still exactly 0
    float support_shadow;
    float support_indirect;
    // 1: accumulate the indirect sums; 0: leave them 0
    uint indirect;
    // 0: every receiver; 1 + k: the receiver at (k & 1, k >> 1) of every 2x2 cell;
    // AMORTISE_REGATHER_SLICE: the receivers `marks` marks (src/passes/amortise.rs)
    uint slice;
} push;

// Row l-major lookup of table `table` (0 log-occlusion, 1 clamped visibility, 2 unclamped
// visibility) at alpha: shine_sh::sphere_blocker::AlphaTable::lookup.
void table_lookup(uint table, float alpha, out float zh[SH_BANDS]) {
    float a = isnan(alpha) ? 0.0 : clamp(alpha, 0.0, 1.0);
    int n = int(push.table_entries);
    float x = a * float(n - 1);
    int i0 = min(int(floor(x)), n - 2);
    float t = x - float(i0);
    int base = int(table) * n * SH_BANDS;
    for (int l = 0; l < SH_BANDS; ++l) {
        float lo = tables.t[base + i0 * SH_BANDS + l];
        float hi = tables.t[base + (i0 + 1) * SH_BANDS + l];
        zh[l] = lo * (1.0 - t) + hi * t;
    }
}

#ifdef SPLAT
// Words of a tile's proxy mask: shine::passes::proxy::TILE_WORDS.
const uint TILE_WORDS = 64u;
// shaders/proxy_tiles.comp: per 8x8 tile, 64 words; bit b of word w set when proxy 32 w + b
// may touch the tile
layout(set = 0, binding = 6, std430) readonly buffer TileMasks {
    uint m[];
} tile_masks;
#endif

void main() {
    uvec2 xy = uvec2(amortise_pixel(gl_GlobalInvocationID.xy, push.slice));
    bool inside = all(lessThan(xy, push.extent));
    ivec2 ixy = ivec2(min(xy, push.extent - 1u));
    vec4 pos = imageLoad(recv_position, ixy);
    bool valid = inside && pos.w > 0.0;
    vec3 p = pos.xyz;
#ifdef SPLAT
    float support = min(push.support_shadow, push.support_indirect);
    uint tiles_x = (push.extent.x + 7u) / 8u;
    uint tile = (xy.y / 8u) * tiles_x + xy.x / 8u;
#endif
    if (!inside) {
        return;
    }
    if (push.slice == AMORTISE_REGATHER_SLICE && imageLoad(marks, ixy).a >= 0.0) {
        return;
    }
    uint base = (xy.y * push.extent.x + xy.x) * uint(SH_COEFFS + 4);
    float acc[SH_COEFFS];
    for (int i = 0; i < SH_COEFFS; ++i) {
        acc[i] = 0.0;
    }
#ifdef PRODUCT
    acc[0] = SH_SQRT_4PI;
#endif
    vec3 indirect = vec3(0.0);
    float omega = 0.0;
    if (valid) {
        vec3 n = normalize(imageLoad(recv_normal, ixy).xyz);
        float cc[SH_BANDS];
        sh_clamped_cosine_zh(cc);
        float hn[SH_COEFFS];
        sh_rotate_zh(cc, n, hn);
        // L~ (unshadowed irradiance), rgb, first 9 coefficients: what D (3 bands) reads
        float lt[27];
        for (int c = 0; c < 3; ++c) {
            for (int k = 0; k < 9; ++k) {
                lt[c * 9 + k] = environment.e[(3 + c) * SH_COEFFS + k];
            }
        }
#ifdef SPLAT
        // The tile's neighbour list, walked in index order (so the sums equal brute force's
        // bit for bit) as one flat loop over its entries: nesting the proxy loop inside a loop
        // over the mask's words made lavapipe 4x slower (docs/performance.md).
        uint count = 0u;
        for (uint w = 0u; w < TILE_WORDS; ++w) {
            count += uint(bitCount(tile_masks.m[tile * TILE_WORDS + w]));
        }
        uint word = 0u;
        uint bits = 0u;
        for (uint j = 0u; j < count; ++j) {
            while (bits == 0u) {
                bits = tile_masks.m[tile * TILE_WORDS + word];
                ++word;
            }
            uint i = (word - 1u) * 32u + uint(findLSB(bits));
            bits &= bits - 1u;
#else
        for (uint i = 0u; i < push.proxy_count; ++i) {
#endif
            vec4 sphere = proxies.p[2u * i];
            vec3 albedo = proxies.p[2u * i + 1u].xyz;
#ifdef SPLAT
            // the depth test of the splat: is p inside the sphere of influence?
            vec3 off = sphere.xyz - p;
            if (!(sphere.w * sphere.w > support * support * dot(off, off))) {
                continue;
            }
#endif
            vec4 s = sh_proxy_self_shadow(p, n, sphere.xyz, sphere.w);
            if (!(s.w > 0.0)) {
                continue;
            }
            vec3 dv = s.xyz - p;
            float dist = length(dv);
            if (!(dist > 0.0)) {
                continue;
            }
            float alpha = min(s.w / dist, 1.0);
            vec3 dir = dv / dist;
            float y[SH_COEFFS];
            sh_basis(dir, y);
            float zh[SH_BANDS];
            float rotated[SH_COEFFS];
#ifdef PRODUCT
            table_lookup(2u, alpha, zh);
            sh_rotate_zh_basis(zh, y, rotated);
            for (int k = 0; k < SH_COEFFS; ++k) {
                rotated[k] = (k == 0 ? SH_SQRT_4PI : 0.0) - rotated[k];
            }
            float product[SH_COEFFS];
            sh_product(acc, rotated, product);
            acc = product;
#else
            table_lookup(0u, alpha, zh);
            sh_rotate_zh_basis(zh, y, rotated);
            for (int k = 0; k < SH_COEFFS; ++k) {
                acc[k] += rotated[k];
            }
#endif
            if (push.indirect != 0u) {
#ifdef PRODUCT
                table_lookup(2u, alpha, zh);
#else
                table_lookup(1u, alpha, zh);
#endif
                // order-3 indirect (paper 002 §5): bands >= 3 of V are dropped
                for (int l = 3; l < SH_BANDS; ++l) {
                    zh[l] = 0.0;
                }
                sh_rotate_zh_basis(zh, y, rotated);
                float vh = sh_dot(rotated, hn);
                // eq. 12, paper 002: the proxy's true solid angle 2π(1 - cos θ), sin θ = α,
                // wherever its (clamped) visibility is not 0 — not the clamped table's DC,
                // which would cancel the indirect fade of §4.1
                if (zh[0] > 0.0) {
                    omega += 2.0 * SH_PI * (1.0 - sqrt(max(0.0, 1.0 - alpha * alpha)));
                }
                vec3 d3 = sh_proxy_d_fit(alpha);
                for (int l = 0; l < SH_BANDS; ++l) {
                    zh[l] = l < 3 ? d3[l] : 0.0;
                }
                sh_rotate_zh_basis(zh, y, rotated);
                vec3 kappa = vec3(0.0);
                for (int k = 0; k < 9; ++k) {
                    kappa += rotated[k] * vec3(lt[k], lt[9 + k], lt[18 + k]);
                }
                indirect += albedo / SH_PI * kappa * vh;
            }
        }
    }
    for (int k = 0; k < SH_COEFFS; ++k) {
        sums.s[base + uint(k)] = acc[k];
    }
    sums.s[base + uint(SH_COEFFS)] = indirect.r;
    sums.s[base + uint(SH_COEFFS) + 1u] = indirect.g;
    sums.s[base + uint(SH_COEFFS) + 2u] = indirect.b;
    sums.s[base + uint(SH_COEFFS) + 3u] = omega;
}
