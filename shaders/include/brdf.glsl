// Metallic-roughness BRDF of the direct pass: Lambert diffuse and GGX specular (Trowbridge-
// Reitz D, height-correlated Smith visibility, Schlick Fresnel), as in the glTF spec appendix B.
#ifndef BRDF_GLSL
#define BRDF_GLSL
#include "color.glsl"

const float BRDF_PI = 3.14159265358979323846;

// GGX alpha of a perceptual roughness (clamped away from a delta lobe).
float brdf_alpha(float roughness) {
    return max(roughness * roughness, 1e-3);
}

// Trowbridge-Reitz (GGX) normal distribution D at cos(n, h) = nh.
float ggx_distribution(float nh, float a) {
    float a2 = a * a;
    float d_denom = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (BRDF_PI * d_denom * d_denom);
}

// f(l, v) for unit n, l, v as its diffuse (Lambert) and specular (GGX) parts; `roughness` is
// perceptual (alpha = roughness^2).
void brdf_metallic_roughness_parts(vec3 n, vec3 l, vec3 v, vec3 base_color, float metallic, float roughness, out vec3 diffuse, out vec3 specular) {
    vec3 h = normalize(l + v);
    float nl = max(dot(n, l), 0.0);
    float nv = max(dot(n, v), 1e-4);
    float nh = max(dot(n, h), 0.0);
    float vh = max(dot(v, h), 0.0);
    float a = brdf_alpha(roughness);
    float a2 = a * a;
    float d = ggx_distribution(nh, a);
    float vis = 0.5 / max(nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2), 1e-6);
    vec3 f0 = mix(vec3(0.04), base_color, metallic);
    vec3 f = f0 + (1.0 - f0) * pow(1.0 - vh, 5.0);
    diffuse = (1.0 - f) * (1.0 - metallic) * base_color / BRDF_PI;
    specular = f * d * vis;
}

// f(l, v) for unit n, l, v; `roughness` is perceptual (alpha = roughness^2).
vec3 brdf_metallic_roughness(vec3 n, vec3 l, vec3 v, vec3 base_color, float metallic, float roughness) {
    vec3 diffuse;
    vec3 specular;
    brdf_metallic_roughness_parts(n, l, v, base_color, metallic, roughness, diffuse, specular);
    return diffuse + specular;
}

// shine::passes::specular::FADE
const float SPECULAR_FADE = 0.1;

// Share of a receiver's specular lobe that the traced specular pass takes
// (shine::passes::specular::trace_weight): 1 up to `limit` - SPECULAR_FADE, a smoothstep down to
// 0 at `limit`; 0 everywhere without the pass (limit <= 0). The SH techniques (HVL, IGI, AAF)
// scale their glossy term by 1 minus it.
float specular_trace_weight(float roughness, float limit) {
    if (limit <= 0.0) {
        return 0.0;
    }
    return 1.0 - smoothstep(limit - SPECULAR_FADE, limit, roughness);
}

// --- Importance sampling of the BRDF above (path tracer) ---
// One-sample mixture: the specular lobe (GGX D sampling of the half vector) with probability
// brdf_specular_probability, else the cosine-weighted hemisphere; brdf_pdf is the mixture's
// solid-angle density, so f·cos/pdf is unbiased for every direction either lobe can produce.

// Orthonormal tangent and bitangent of unit n (Duff et al. 2017, branchless).
void brdf_basis(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction about n (density cos / π).
vec3 sample_cosine(vec3 n, vec2 xi) {
    vec3 t;
    vec3 b;
    brdf_basis(n, t, b);
    float r = sqrt(xi.x);
    float phi = 2.0 * BRDF_PI * xi.y;
    return normalize(r * cos(phi) * t + r * sin(phi) * b + sqrt(max(0.0, 1.0 - xi.x)) * n);
}

// GGX half vector about n (density D(h)·(n·h) over half vectors).
vec3 sample_ggx_half(vec3 n, float a, vec2 xi) {
    vec3 t;
    vec3 b;
    brdf_basis(n, t, b);
    float a2 = a * a;
    float cos_theta = sqrt(max(0.0, (1.0 - xi.x) / (1.0 + (a2 - 1.0) * xi.x)));
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    float phi = 2.0 * BRDF_PI * xi.y;
    return normalize(sin_theta * cos(phi) * t + sin_theta * sin(phi) * b + cos_theta * n);
}

// Probability of sampling the specular lobe: its normal-incidence weight (F0 luminance)
// against the diffuse weight, kept within [0.1, 0.9] while both lobes exist.
float brdf_specular_probability(vec3 base_color, float metallic) {
    float ws = luminance(mix(vec3(0.04), base_color, metallic));
    float wd = luminance(base_color) * (1.0 - metallic);
    if (wd <= 0.0) {
        return 1.0;
    }
    return clamp(ws / max(ws + wd, 1e-6), 0.1, 0.9);
}

// Solid-angle density of brdf_sample's mixture for direction l.
float brdf_pdf(vec3 n, vec3 l, vec3 v, float p_specular, float roughness) {
    float nl = dot(n, l);
    if (nl <= 0.0) {
        return 0.0;
    }
    vec3 h = normalize(l + v);
    float nh = max(dot(n, h), 0.0);
    float vh = max(dot(v, h), 1e-6);
    float a = brdf_alpha(roughness);
    float spec = ggx_distribution(nh, a) * nh / (4.0 * vh);
    return (1.0 - p_specular) * nl / BRDF_PI + p_specular * spec;
}

// Samples a direction for brdf_metallic_roughness at (n, v) from three uniform numbers.
vec3 brdf_sample(vec3 n, vec3 v, float p_specular, float roughness, vec3 xi) {
    if (xi.z < p_specular) {
        vec3 h = sample_ggx_half(n, brdf_alpha(roughness), xi.xy);
        return reflect(-v, h);
    }
    return sample_cosine(n, xi.xy);
}

// shine::passes::brdf_tables::DIFFUSE_FRESNEL_SCALE, DIFFUSE_FRESNEL_POWER
const float BRDF_DIFFUSE_FRESNEL_SCALE = 0.0279;
const float BRDF_DIFFUSE_FRESNEL_POWER = 2.55;

// Diffuse and specular weights of the metallic-roughness material for indirect light (HVL, IGI,
// AAF), shine::passes::brdf_tables::indirect_weights: ks = Schlick's Fresnel at the mirror
// direction (v . h = n . v); kd = (1 - F_d)(1 - metallic) albedo with F_d the direct pass's
// F(v . h) averaged over a cosine-distributed hemisphere of light directions
// (brdf_tables::diffuse_fresnel_factor, a fit).
void brdf_indirect_weights(vec3 albedo, float metallic, float n_dot_v, out vec3 kd, out vec3 ks) {
    vec3 f0 = mix(vec3(0.04), albedo, metallic);
    float grazing = 1.0 - clamp(n_dot_v, 0.0, 1.0);
    ks = f0 + (1.0 - f0) * pow(grazing, 5.0);
    vec3 f_diffuse = f0 + (1.0 - f0) * (BRDF_DIFFUSE_FRESNEL_SCALE * pow(grazing, BRDF_DIFFUSE_FRESNEL_POWER));
    kd = (1.0 - f_diffuse) * (1.0 - metallic) * albedo;
}

// shine::passes::brdf_tables::table_fresnel_weight (an n.v approximation: the tables' Fresnel varies
// with each direction's v.h). Weight of the GGX tables' glossy row (they hold the exact dielectric Fresnel, eta = 1.5): the
// material's Schlick F over the tables' F at the mirror direction (v . h = n . v), Schlick with
// F0 = 0.04 standing for the latter: 1 for dielectrics, about albedo / 0.04 at normal view for
// metals.
vec3 brdf_table_fresnel_weight(vec3 ks, float n_dot_v) {
    float f_table = 0.04 + 0.96 * pow(1.0 - clamp(n_dot_v, 0.0, 1.0), 5.0);
    return ks / f_table;
}

#endif
