// Harmonics Virtual Lights (paper 003): the HVL cache record and the zonal helpers the HVL
// passes share. Include after sh.glsl (SH_BANDS defined). Every function mirrors a Rust
// function named in its comment (shine::reference::hvl or shine-sh) with the same formula.
#ifndef HVL_GLSL
#define HVL_GLSL

#ifndef SH_GLSL
#error "include sh.glsl before hvl.glsl"
#endif

// Most emission bands an HVL record stores (paper 003 §3: 0-5 bands for the emission).
#define HVL_EMISSION_MAX_BANDS 5

// One HVL of the cache, std430, 80 bytes: shine::passes::hvl::Hvl.
struct Hvl {
    // xyz: world position y_j of the HVL centre; w: radius r_j (scaled), 0 for an empty cell
    vec4 position_radius;
    // xyz: unit normal n_j; w: distance d_j to the primary light
    vec4 normal_distance;
    // rgb: flux Phi_j (W); a: 1 for a valid HVL, 0 for an empty cell
    vec4 flux;
    // ZH coefficients (about n_j) of the sender's F' (paper 003 eq. 20)
    float emission[HVL_EMISSION_MAX_BANDS];
    // identity: the sample's sequence (the flux distribution: light index in the scene * 6 +
    // its RSM face among the light's, shine::passes::hvl::flux::sequence_id; 0 on the grid)
    // and its index in that sequence or its grid cell; survives reordering (IGI's sets)
    uint light;
    uint sample_index;
    // the samples its light keeps (n_k; the cell count on the grid): a light's records are
    // consecutive from slot - sample_index; 0 for an empty slot of the flux distribution
    uint light_samples;
};

// One HVL as the gather reads it: shine::passes::hvl::GatherHvl, written from the cache by
// hvl_gather_prep.comp with the per-HVL terms of the gather precomputed. The records live in an
// RGBA32F image, not a storage buffer: llvmpipe loads an image texel about 4x faster than a
// storage buffer's vec4 (docs/performance.md). Record j is the HVL_RECORD_TEXELS texels
// x = HVL_RECORD_TEXELS (j mod HVL_RECORDS_PER_ROW) + field, y = j / HVL_RECORDS_PER_ROW
// (shine::passes::hvl::RECORDS_PER_ROW), one per field:
const uint HVL_RECORDS_PER_ROW = 512u;
// xyz: centre y_j; w: radius r_j, 0 for an empty cell (skipped)
const uint HVL_RECORD_POSITION_RADIUS = 0u;
// xyz: unit normal n_j; w: 1 / (pi r_j^2), eq. 21's denominator (hvl_geometric_factor_of)
const uint HVL_RECORD_NORMAL_AREA = 1u;
// rgb: flux Phi_j; a: a_0 of the emission polynomial (hvl_zh_poly)
const uint HVL_RECORD_FLUX_E0 = 2u;
// a_1..a_4 of the emission polynomial
const uint HVL_RECORD_EMISSION = 3u;
// x: the HVL's light (Hvl.light), y: its sample index (Hvl.sample_index), z: the samples its
// light keeps (Hvl.light_samples), as floats (exact below 2^24): its identity, which keys and
// stratifies the sampled shadows' draw (hvl_gather.comp)
const uint HVL_RECORD_IDENTITY = 4u;
// Texels per record (shine::passes::hvl::RECORD_TEXELS).
const uint HVL_RECORD_TEXELS = 5u;

// The texel of field `field` (HVL_RECORD_*) of record j.
ivec2 hvl_record_texel(uint j, uint field) {
    return ivec2(int((j % HVL_RECORDS_PER_ROW) * HVL_RECORD_TEXELS + field), int(j / HVL_RECORDS_PER_ROW));
}

// shine::reference::hvl::sender_emission_zh: ZH coefficient l of the Lambert sender's F'
// (paper 003 eq. 20; albedo in the flux, cosine in G): 1/pi in every direction, band 0 only.
float hvl_sender_emission(int l) {
    return l == 0 ? SH_SQRT_4PI / SH_PI : 0.0;
}

// shine::reference::hvl::zh_poly: a ZH vector (about axis a) evaluated at direction b,
// cos_angle = a . b, sum_l zh_l sqrt((2l+1)/(4 pi)) P_l(cos_angle) over the first `bands`
// bands (shine::reference::hvl::zh_eval), as a polynomial in cos_angle: a[k] the coefficient
// of cos_angle^k (P_l expanded by the recurrence of sh_legendre_all on coefficient rows).
void hvl_zh_poly(float zh[8], int bands, out float a[HVL_EMISSION_MAX_BANDS]) {
    float prev[HVL_EMISSION_MAX_BANDS];
    float cur[HVL_EMISSION_MAX_BANDS];
    SH_UNROLL for (int k = 0; k < HVL_EMISSION_MAX_BANDS; ++k) {
        prev[k] = 0.0;
        cur[k] = k == 0 ? 1.0 : 0.0;
        a[k] = 0.0;
    }
    SH_UNROLL for (int l = 0; l < HVL_EMISSION_MAX_BANDS; ++l) {
        // From P_(l-1) (cur) and P_(l-2) (prev): l P_l = (2l - 1) x P_(l-1) - (l - 1) P_(l-2).
        if (l > 0) {
            float lf = float(l - 1);
            float next[HVL_EMISSION_MAX_BANDS];
            SH_UNROLL for (int k = 0; k < HVL_EMISSION_MAX_BANDS; ++k) {
                float shifted = 0.0;
                if (k > 0) {
                    shifted = cur[k - 1];
                }
                next[k] = ((2.0 * lf + 1.0) * shifted - lf * prev[k]) / (lf + 1.0);
            }
            SH_UNROLL for (int k = 0; k < HVL_EMISSION_MAX_BANDS; ++k) {
                prev[k] = cur[k];
                cur[k] = next[k];
            }
        }
        float w = l < bands ? zh[l] * sqrt(float(2 * l + 1) / (4.0 * SH_PI)) : 0.0;
        SH_UNROLL for (int k = 0; k < HVL_EMISSION_MAX_BANDS; ++k) {
            a[k] += w * cur[k];
        }
    }
}

// shine::reference::hvl::poly_eval: sum_k a[k] x^k (Horner)
float hvl_poly_eval(float a[HVL_EMISSION_MAX_BANDS], float x) {
    float s = a[HVL_EMISSION_MAX_BANDS - 1];
    SH_UNROLL for (int k = HVL_EMISSION_MAX_BANDS - 2; k >= 0; --k) {
        s = s * x + a[k];
    }
    return s;
}

// shine::reference::hvl::zh_dot: dot product of two ZH vectors rotated to axes at cos_angle,
// sum_l f_l g_l P_l(cos_angle) (the O(n) zonal path of paper 003 §6.3)
float hvl_zh_dot(float f[SH_BANDS], float g[SH_BANDS], float cos_angle) {
    float p[SH_BANDS + 1];
    sh_legendre_all(clamp(cos_angle, -1.0, 1.0), p);
    float s = 0.0;
    SH_UNROLL for (int l = 0; l < SH_BANDS; ++l) {
        s += f[l] * g[l] * p[l];
    }
    return s;
}

#endif // HVL_GLSL
