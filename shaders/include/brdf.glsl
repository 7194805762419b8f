// Metallic-roughness BRDF of the direct pass: Lambert diffuse and GGX specular (Trowbridge-
// Reitz D, height-correlated Smith visibility, Schlick Fresnel), as in the glTF spec appendix B.
#ifndef BRDF_GLSL
#define BRDF_GLSL

const float BRDF_PI = 3.14159265358979323846;

// f(l, v) for unit n, l, v; `roughness` is perceptual (alpha = roughness^2).
vec3 brdf_metallic_roughness(vec3 n, vec3 l, vec3 v, vec3 base_color, float metallic, float roughness) {
    vec3 h = normalize(l + v);
    float nl = max(dot(n, l), 0.0);
    float nv = max(dot(n, v), 1e-4);
    float nh = max(dot(n, h), 0.0);
    float vh = max(dot(v, h), 0.0);
    float a = max(roughness * roughness, 1e-3);
    float a2 = a * a;
    float d_denom = nh * nh * (a2 - 1.0) + 1.0;
    float d = a2 / (BRDF_PI * d_denom * d_denom);
    float vis = 0.5 / max(nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2), 1e-6);
    vec3 f0 = mix(vec3(0.04), base_color, metallic);
    vec3 f = f0 + (1.0 - f0) * pow(1.0 - vh, 5.0);
    vec3 diffuse = (1.0 - f) * (1.0 - metallic) * base_color / BRDF_PI;
    return diffuse + f * d * vis;
}

#endif
