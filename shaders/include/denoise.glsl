// The denoiser of the traced signals (issue 47; src/passes/denoise.rs): an edge-stopping
// à-trous filter (SVGF, Schied et al. 2017: a 5×5 B3-spline kernel whose taps spread by 2^i at
// iteration i, weighted by geometry and by the luminance difference over the local standard
// deviation) whose spatial extent is the reflected lobe's footprint in the image (after NRD's
// hit-distance-driven radius): a mirror keeps its pixel, a rough lobe gathers from as far as
// its reflection blurs. CPU twin: shine::reference::denoise (same names without the denoise_
// prefix); tests/denoise.rs compares the passes with it.
#ifndef DENOISE_GLSL
#define DENOISE_GLSL
#include "color.glsl"

// Share f of the GGX half-vector distribution inside the lobe the filter spans: the NDF's CDF
// over tan²θ_h is t² / (α² + t²), so tan θ_h = α sqrt(f / (1 − f)); f = 1/2: the median.
const float DENOISE_LOBE_FRACTION = 0.5;
// Widest reflected half-angle the filter spans, radians (lobes rougher than specular.limit
// are the SH techniques').
const float DENOISE_MAX_LOBE_ANGLE = 1.0;
// Least parallax the footprint takes: what nearly touches the receiver is seen sharp, but two
// rays a pixel leave it as noisy as the rest (0.5: builtin:metals' gold 0.208 -> 0.204 of the
// truth, tests/specular.rs's rough sphere over a floor 0.345 -> 0.323).
const float DENOISE_MIN_PARALLAX = 0.5;
// Largest footprint radius, pixels (3 iterations reach 14 pixels).
const float DENOISE_MAX_RADIUS = 16.0;
// A footprint under this radius (pixels) is sharp: the lobe's reflection spreads less than a
// pixel, so its rays agree and there is no noise to filter or to clamp. The pixel is kept as
// traced: a mirror's lone bright pixel is a reflected highlight, not a firefly.
const float DENOISE_SHARP_RADIUS = 0.5;
// σ_p: a neighbour's distance off the centre's tangent plane, relative to the view distance.
const float DENOISE_PLANE_SIGMA = 0.02;
// Least normal tolerance 1 − cos φ (a mirror's lobe would otherwise part a plane's own f16
// normals).
const float DENOISE_MIN_NORMAL_TOLERANCE = 1e-4;
// σ_r: roughness difference over which two lobes stop mixing.
const float DENOISE_ROUGHNESS_SIGMA = 0.05;
// σ_l of SVGF's luminance weight, in standard deviations of the centre (SVGF's 4 kept the
// gold sphere of builtin:metals at 0.215 of the truth, 8 at 0.208; docs/quality.md).
const float DENOISE_LUMINANCE_SIGMA = 8.0;
// Smallest demodulation weight share · ks divided by (keeps grazing, barely traced pixels
// finite).
const float DENOISE_MIN_WEIGHT = 1e-3;
// The firefly clamp: a pixel's luminance at most this many times the largest of its 3×3
// neighbours' on the same surface (denoise_clamp_roughness: whatever their roughness, if their
// lobe is no wider than its own); a local maximum of ordinary noise is left to the filter, a
// lone sample that found a bright light is cut.
const float DENOISE_FIREFLY_RATIO = 2.0;
// ε of the luminance weight (a flat region's zero variance keeps equal neighbours only).
const float DENOISE_LUMINANCE_EPSILON = 1e-6;
// A neighbour counts for the firefly clamp and the variance when its geometry weight is at
// least this.
const float DENOISE_MATCH = 0.25;

// The diffuse signals' normal tolerance 1 − cos φ (the sky's visibility, HVL's near field).
// Their "lobe" is the hemisphere, whose width would mix two walls at their corner, where the
// visibility and the near light change; so the receivers' own match instead:
// exp(−(1 − n_p·n_q) / t) ≈ (n_p·n_q)^(1/t), and 1/32 is the upsample's normal power 32
// (paper 002 eq. 11) that the bilateral sky filter used.
const float DENOISE_DIFFUSE_NORMAL_TOLERANCE = 0.03125;

// Least radius of a diffuse footprint driven by hit distances, pixels (rays that meet a wall
// at once still leave noise).
const float DENOISE_DIFFUSE_MIN_RADIUS = 1.0;

// A diffuse footprint of `world` units seen at distance `dist` from the eye, in pixels of angle
// `pixel_angle`, between DENOISE_DIFFUSE_MIN_RADIUS and DENOISE_MAX_RADIUS: HVL's near field's,
// `world` a multiple of its rays' mean hit distance (NRD's diffuse filters: light found close
// by changes over that distance).
float denoise_world_radius(float world, float dist, float pixel_angle) {
    return clamp(world / (dist * pixel_angle), DENOISE_DIFFUSE_MIN_RADIUS, DENOISE_MAX_RADIUS);
}

// The reflected lobe's half-angle θ for GGX α: twice the half vector's angle.
float denoise_lobe_angle(float alpha) {
    float t = alpha * sqrt(DENOISE_LOBE_FRACTION / (1.0 - DENOISE_LOBE_FRACTION));
    return min(2.0 * atan(t), DENOISE_MAX_LOBE_ANGLE);
}

// tan θ of the reflected lobe.
float denoise_lobe_tan(float alpha) {
    return tan(denoise_lobe_angle(alpha));
}

// How far apart two normals may be for their reflections to share a lobe: 1 − cos θ (at
// least DENOISE_MIN_NORMAL_TOLERANCE). On a curved mirror neighbours reflect other
// directions and stay apart; on a rough lobe they mix (NRD's lobe-driven normal weight).
float denoise_normal_tolerance(float alpha) {
    return max(1.0 - cos(denoise_lobe_angle(alpha)), DENOISE_MIN_NORMAL_TOLERANCE);
}

// Footprint radius in pixels of a lobe of GGX α whose reflected points lie at parallax
// d / (z + d) (d the hit distance, z the receiver's distance from the eye; 1 where rays
// escape; at least DENOISE_MIN_PARALLAX): the reflection of a point spread by tan θ at d,
// seen from z + d, spans tan θ · d / (z + d) radians; `pixel_angle` is the angle one pixel
// subtends there.
float denoise_radius(float alpha, float parallax, float pixel_angle) {
    return min(denoise_lobe_tan(alpha) * max(parallax, DENOISE_MIN_PARALLAX) / pixel_angle, DENOISE_MAX_RADIUS);
}

// Least claim of a traced pixel on the frame's specular rays (a mirror's lobe still needs
// its ray).
const float DENOISE_RAY_FLOOR = 0.02;
// A lobe narrower than this tan θ keeps its specular.samples rays when the rays are shared
// (denoise_rays): the filter cannot widen it (its footprint stays under a pixel), so rays taken
// from it are grain nothing smooths (builtin:metals' chrome, 0.03, tan θ 0.002: 0.092 of the
// truth at 2 rays, 0.121 at the ~1.2 the shared budget left it). 0.01 (a half-angle of 0.6°,
// roughness ≈ 0.07) keeps builtin:metals' and builtin:room's chrome (0.03, 0.05) and shares
// the silver's (0.1, tan θ 0.02).
const float DENOISE_RAY_KEEP_TAN = 0.01;
// Most rays one pixel takes, in multiples of specular.samples.
const float DENOISE_RAY_MAX_FACTOR = 4.0;

// A traced pixel's claim on the frame's specular rays: its trace share times the lobe's
// width tan θ plus a floor (the wider the lobe, the more its rays disagree; a mirror's two
// rays see the same point). 0 where nothing is traced.
float denoise_ray_weight(float alpha, float share) {
    return share > 0.0 ? share * (DENOISE_RAY_FLOOR + denoise_lobe_tan(alpha)) : 0.0;
}

// Rays of a pixel of claim `weight` when `samples` rays per traced pixel are shared among
// `traced` pixels claiming `total` in all: one each, plus its claim's share of the other
// (samples − 1) · traced, at most DENOISE_RAY_MAX_FACTOR · samples, rounded up with
// probability its fraction (`u` in [0, 1)) so the frame's total stays the budget on average.
uint denoise_ray_count(float weight, uint samples, float traced, float total, float u) {
    float spare = float(max(samples, 1u) - 1u);
    float n = total > 0.0 ? 1.0 + spare * traced * weight / total : float(samples);
    return uint(floor(min(n, DENOISE_RAY_MAX_FACTOR * float(samples)) + u));
}

// Rays of a traced pixel of GGX α and trace share `share` when the frame's rays are shared
// (specular.adaptive): denoise_ray_count of its claim, but at least `samples` for a lobe
// narrower than DENOISE_RAY_KEEP_TAN (those rays come on top of the budget: a frame spends at
// most (samples − 1) more rays per such pixel than `samples` per traced pixel).
uint denoise_rays(float alpha, float share, uint samples, float traced, float total, float u) {
    uint n = denoise_ray_count(denoise_ray_weight(alpha, share), samples, traced, total, u);
    return denoise_lobe_tan(alpha) < DENOISE_RAY_KEEP_TAN ? max(n, max(samples, 1u)) : n;
}

// The roughness neighbour q is compared at in the firefly clamp's geometry test: a smoother
// neighbour (a narrower lobe) counts as the centre's own. A wider lobe is a blur of a narrower
// one over the same surroundings and a blur never exceeds the largest value it averages, so
// a neighbour as smooth or smoother bounds the centre; a rougher one does not (a mirror beside
// a rough tile may rightly hold a light's highlight many times its neighbours').
float denoise_clamp_roughness(float rough_p, float rough_q) {
    return max(rough_p, rough_q);
}

// The 3-tap gaussian of SVGF's variance prefilter (offset i in -1..1): 1/4, 1/2, 1/4. The
// luminance weight of the specular's à-trous divides by the centre's deviation from its 3×3
// variance blurred so (SVGF eq. 5): two rays leave the 3×3 variance itself noisy.
float denoise_variance_kernel(int i) {
    return i == 0 ? 0.5 : 0.25;
}

// The B3-spline tap of offset i in -2..2: 1/16, 1/4, 3/8, 1/4, 1/16.
float denoise_kernel(int i) {
    int a = abs(i);
    return a == 0 ? 0.375 : (a == 1 ? 0.25 : 0.0625);
}

// How much neighbour q (position, normal, roughness) stands for centre p seen from `dist_p`,
// whose lobe's normal tolerance is `tolerance` (denoise_normal_tolerance): off p's tangent
// plane, normals apart (exp(−(1 − n_p·n_q) / tolerance), about exp(−φ²/θ²)), roughness apart.
float denoise_geometry_weight(vec3 x_p, vec3 n_p, float dist_p, float rough_p, float tolerance, vec3 x_q, vec3 n_q, float rough_q) {
    float plane = abs(dot(n_p, x_q - x_p)) / (DENOISE_PLANE_SIGMA * dist_p);
    float normal = (1.0 - dot(n_p, n_q)) / tolerance;
    return exp(-plane - normal - abs(rough_p - rough_q) / DENOISE_ROUGHNESS_SIGMA);
}

// SVGF's luminance weight: exp(−|l_p − l_q| / (σ_l sqrt(var_p) + ε)) (the diffuse variant
// passes max(var_p, var_q): denoise_atrous.comp).
float denoise_luminance_weight(float l_p, float l_q, float variance) {
    return exp(-abs(l_p - l_q) / (DENOISE_LUMINANCE_SIGMA * sqrt(max(variance, 0.0)) + DENOISE_LUMINANCE_EPSILON));
}

// What an RGBA16F texel of the filter holds: each channel at most the half float's largest
// finite value (a variance, luminance², overflows first; inf would turn 0 · inf into NaN).
vec4 denoise_storable(vec4 v) {
    return min(v, vec4(HALF_MAX));
}

// The footprint's gaussian at squared pixel offset `offset2` for `radius` pixels (σ = radius);
// under DENOISE_SHARP_RADIUS, the centre alone.
float denoise_lobe_weight(float offset2, float radius) {
    if (radius < DENOISE_SHARP_RADIUS) {
        return offset2 == 0.0 ? 1.0 : 0.0;
    }
    return exp(-offset2 / (2.0 * radius * radius));
}

#endif
