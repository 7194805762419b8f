// The environment light (src/gpu_scene/environment.rs): an equirectangular RGBA32F texture baked
// from shine_scene::Environment::radiance, black without an environment. Define
// ENVIRONMENT_BINDING and ENVIRONMENT_SAMPLER_BINDING before the #include; the sampler must be
// linear, repeating in u and clamped in v.
//
// Mapping: u = atan(d.x, -d.z) / 2π + 1/2, v = acos(d.y) / π (+Y up, v = 0 at the zenith).
#ifndef ENVIRONMENT_GLSL
#define ENVIRONMENT_GLSL

#if !defined(ENVIRONMENT_BINDING) || !defined(ENVIRONMENT_SAMPLER_BINDING)
#error "define ENVIRONMENT_BINDING and ENVIRONMENT_SAMPLER_BINDING before including environment.glsl"
#endif

layout(set = 0, binding = ENVIRONMENT_BINDING) uniform texture2D environment;
layout(set = 0, binding = ENVIRONMENT_SAMPLER_BINDING) uniform sampler environment_sampler;

const float ENVIRONMENT_PI = 3.14159265358979323846;

// Texture coordinates of unit direction `d` (the mapping above; shine's
// gpu_scene::environment::texcoord).
vec2 environment_texcoord(vec3 d) {
    // atan(0, 0) is undefined: straight up or down any azimuth will do.
    float u = abs(d.x) + abs(d.z) > 0.0 ? atan(d.x, -d.z) / (2.0 * ENVIRONMENT_PI) + 0.5 : 0.5;
    return vec2(u, acos(clamp(d.y, -1.0, 1.0)) / ENVIRONMENT_PI);
}

// The unit direction at texture coordinates `uv` (the inverse of environment_texcoord; shine's
// gpu_scene::environment::direction).
vec3 environment_direction(vec2 uv) {
    float phi = (uv.x - 0.5) * 2.0 * ENVIRONMENT_PI;
    float theta = uv.y * ENVIRONMENT_PI;
    return vec3(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
}

// Radiance arriving from direction `dir` (need not be unit).
vec3 environment_radiance(vec3 dir) {
    vec2 uv = environment_texcoord(normalize(dir));
    return textureLod(sampler2D(environment, environment_sampler), uv, 0.0).rgb;
}

#endif
