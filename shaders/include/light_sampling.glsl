// Next-event estimation for the area lights of the reference path tracer: emissive triangles
// and the environment, sampled from the tables of src/reference/light_tables.rs (layout there)
// and weighted against BRDF sampling by the power heuristic (Veach 1997, §9.2.2, β = 2).
//
// The includer includes path.glsl (vertices, indices, materials, random numbers) and
// environment.glsl first, and defines LIGHT_TABLES_BINDING.
#ifndef LIGHT_SAMPLING_GLSL
#define LIGHT_SAMPLING_GLSL

#ifdef PATH_SCENE_TEXELS
// The tables' words in an R32UI image (rows of TRACE_ROW_TEXELS): path.glsl's PATH_SCENE_TEXELS.
layout(set = 0, binding = LIGHT_TABLES_BINDING, r32ui) readonly uniform uimage2D light_table_texels;

// Word k of the tables.
uint light_table(uint k) {
    return imageLoad(light_table_texels, trace_texel(k)).x;
}
#else
layout(set = 0, binding = LIGHT_TABLES_BINDING, std430) readonly buffer LightTables {
    uint w[];
} light_tables;

// Word k of the tables.
uint light_table(uint k) {
    return light_tables.w[k];
}
#endif

uint light_emitter_count() {
    return light_table(0u);
}

bool light_environment_on() {
    return light_table(2u) != 0u;
}

float light_word(uint k) {
    return uintBitsToFloat(light_table(k));
}

// The first i < count whose CDF value (at `offset`) exceeds xi: the bin xi falls in.
uint light_search(uint offset, uint count, float xi) {
    uint lo = 0u;
    uint hi = count - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (light_word(offset + mid) > xi) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    return lo;
}

// The probability of bin i of the CDF at `offset`.
float light_bin(uint offset, uint i) {
    return light_word(offset + i) - (i > 0u ? light_word(offset + i - 1u) : 0.0);
}

// The power heuristic's weight of a strategy of density a against one of density b.
float light_mis(float a, float b) {
    if (!(a > 0.0)) {
        return 0.0;
    }
    float r = b / a;
    return 1.0 / (1.0 + r * r);
}

// Solid-angle density, seen from `x`, of picking with probability p the triangle (p0, p1, p2)
// and the point `y` on it.
float light_area_pdf(float p, vec3 p0, vec3 p1, vec3 p2, vec3 x, vec3 y) {
    vec3 ng = cross(p1 - p0, p2 - p0);
    float twice_area = length(ng);
    vec3 d = y - x;
    float dist2 = dot(d, d);
    float cos_y = abs(dot(ng, d)) / (twice_area * sqrt(dist2));
    return cos_y > 0.0 ? p * dist2 / (0.5 * twice_area * cos_y) : 0.0;
}

// The probability of picking triangle `tri` (0 for one that is never picked).
float light_triangle_probability(uint tri) {
    return light_word(light_table(6u) + tri);
}

// Solid-angle density, seen from `x`, of picking emissive triangle `tri` (of the world
// vertices) and the point `y` on it: the MIS weight of a BRDF-sampled ray that hit it.
float light_triangle_pdf(uint tri, vec3 x, vec3 y) {
    float p = light_triangle_probability(tri);
    if (p <= 0.0) {
        return 0.0;
    }
    vec3 p0 = path_vertex(4u * path_index(3u * tri)).xyz;
    vec3 p1 = path_vertex(4u * path_index(3u * tri + 1u)).xyz;
    vec3 p2 = path_vertex(4u * path_index(3u * tri + 2u)).xyz;
    return light_area_pdf(p, p0, p1, p2, x, y);
}

// Picks an emissive triangle and a uniform point on it; returns the direction from `x`, the
// distance, the emitted radiance towards x and the solid-angle density (0: nothing sampled).
float light_sample_triangle(vec3 x, vec3 xi, out vec3 l, out float dist, out vec3 radiance) {
    uint count = light_emitter_count();
    uint k = light_search(light_table(4u), count, xi.x);
    uint tri = light_table(light_table(5u) + k);
    uint i0 = path_index(3u * tri);
    uint i1 = path_index(3u * tri + 1u);
    uint i2 = path_index(3u * tri + 2u);
    // Uniform on the triangle: b1 = 1 − √ξ₁, b2 = √ξ₁ ξ₂.
    float s = sqrt(xi.y);
    vec3 b = vec3(1.0 - s, s * (1.0 - xi.z), s * xi.z);
    vec3 p0 = path_vertex(4u * i0).xyz;
    vec3 p1 = path_vertex(4u * i1).xyz;
    vec3 p2 = path_vertex(4u * i2).xyz;
    vec3 y = b.x * p0 + b.y * p1 + b.z * p2;
    vec3 d = y - x;
    dist = length(d);
    l = d / max(dist, 1e-20);
    float pdf = light_area_pdf(light_triangle_probability(tri), p0, p1, p2, x, y);
    vec2 uv = b.x * path_vertex(4u * i0 + 3u).xy + b.y * path_vertex(4u * i1 + 3u).xy + b.z * path_vertex(4u * i2 + 3u).xy;
    radiance = surface_emission(floatBitsToUint(path_vertex(4u * i0).w), uv);
    return pdf;
}

// Solid-angle density of sampling direction `dir` (unit) from the environment tables; the
// twin of shine::reference::light_tables::environment_pdf.
float light_environment_pdf(vec3 dir) {
    uint w = light_table(2u);
    uint h = light_table(3u);
    if (w == 0u) {
        return 0.0;
    }
    float sin_theta = sqrt(max(1.0 - dir.y * dir.y, 0.0));
    if (sin_theta <= 0.0) {
        return 0.0;
    }
    vec2 uv = environment_texcoord(dir);
    uint i = min(uint(uv.x * float(w)), w - 1u);
    uint j = min(uint(uv.y * float(h)), h - 1u);
    uint marginal = light_table(7u);
    float p = light_bin(marginal, j) * light_bin(marginal + h + j * w, i);
    return p * float(w * h) / (2.0 * ENVIRONMENT_PI * ENVIRONMENT_PI * sin_theta);
}

// Samples a direction from the environment tables: a row, a texel, a uniform point of it.
// Returns the solid-angle density (0: nothing sampled).
float light_sample_environment(vec3 xi, out vec3 l) {
    uint w = light_table(2u);
    uint h = light_table(3u);
    uint marginal = light_table(7u);
    uint j = light_search(marginal, h, xi.x);
    uint i = light_search(marginal + h + j * w, w, xi.y);
    // The point within the texel: a fresh number (the search's leftovers are correlated).
    l = environment_direction(vec2((float(i) + xi.z) / float(w), (float(j) + rand()) / float(h)));
    return light_environment_pdf(l);
}

#endif
