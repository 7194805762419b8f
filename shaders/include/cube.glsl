// Tiny environment cubes (paper 001, "Environment maps"): CUBE_SIDE x CUBE_SIDE texels on each
// of six faces around an object, a directional table of the light reaching it. Texel t =
// face * CUBE_SIDE^2 + row * CUBE_SIDE + column; faces +x, -x, +y, -y, +z, -z. Rust twins:
// shine::passes::cubes::{texel_direction, texel_of, texel_solid_angle}, unit-tested there
// (not tied to these by a GPU test yet); tests/cubes.rs checks the cubes end to end against
// the path tracer.
#ifndef CUBE_GLSL
#define CUBE_GLSL

// The paper's "ideal size": 6x6 texels a face (shine::passes::cubes::SIDE).
const uint CUBE_SIDE = 6u;
const uint CUBE_TEXELS = 6u * CUBE_SIDE * CUBE_SIDE;

// The direction through face coordinates (u, v) in [-1, 1]^2 of `face` (not normalised).
vec3 cube_face_direction(uint face, float u, float v) {
    switch (face) {
    case 0u: return vec3(1.0, -v, -u);
    case 1u: return vec3(-1.0, -v, u);
    case 2u: return vec3(u, 1.0, v);
    case 3u: return vec3(u, -1.0, -v);
    case 4u: return vec3(u, -v, 1.0);
    default: return vec3(-u, -v, -1.0);
    }
}

// The unit direction through texel t at sub-texel position s in [0, 1]^2 (0.5: the centre).
vec3 cube_texel_direction(uint t, vec2 s) {
    uint face = t / (CUBE_SIDE * CUBE_SIDE);
    uint row = (t / CUBE_SIDE) % CUBE_SIDE;
    uint column = t % CUBE_SIDE;
    vec2 uv = (vec2(column, row) + s) * (2.0 / float(CUBE_SIDE)) - 1.0;
    return normalize(cube_face_direction(face, uv.x, uv.y));
}

// The texel whose square holds direction d (any length > 0).
uint cube_texel_of(vec3 d) {
    vec3 a = abs(d);
    uint face;
    vec2 uv;
    if (a.x >= a.y && a.x >= a.z) {
        face = d.x > 0.0 ? 0u : 1u;
        uv = d.x > 0.0 ? vec2(-d.z, -d.y) / a.x : vec2(d.z, -d.y) / a.x;
    } else if (a.y >= a.z) {
        face = d.y > 0.0 ? 2u : 3u;
        uv = d.y > 0.0 ? vec2(d.x, d.z) / a.y : vec2(d.x, -d.z) / a.y;
    } else {
        face = d.z > 0.0 ? 4u : 5u;
        uv = d.z > 0.0 ? vec2(d.x, -d.y) / a.z : vec2(-d.x, -d.y) / a.z;
    }
    uvec2 cr = uvec2(clamp((uv + 1.0) * (0.5 * float(CUBE_SIDE)), vec2(0.0), vec2(float(CUBE_SIDE) - 0.5)));
    return face * CUBE_SIDE * CUBE_SIDE + cr.y * CUBE_SIDE + cr.x;
}

// The solid angle of texel t: sum over its corners of ±atan(xy / sqrt(x² + y² + 1)).
float cube_texel_solid_angle(uint t) {
    uint row = (t / CUBE_SIDE) % CUBE_SIDE;
    uint column = t % CUBE_SIDE;
    float step = 2.0 / float(CUBE_SIDE);
    vec2 lo = vec2(column, row) * step - 1.0;
    vec2 hi = lo + step;
    float a = 0.0;
    a += atan(hi.x * hi.y, sqrt(hi.x * hi.x + hi.y * hi.y + 1.0));
    a -= atan(lo.x * hi.y, sqrt(lo.x * lo.x + hi.y * hi.y + 1.0));
    a -= atan(hi.x * lo.y, sqrt(hi.x * hi.x + lo.y * lo.y + 1.0));
    a += atan(lo.x * lo.y, sqrt(lo.x * lo.x + lo.y * lo.y + 1.0));
    return a;
}

#endif
