// Sky filter (issue 16, item 7; src/passes/sky.rs): the sky pass's few rays leave noise in the
// visibility A, most where little sky is open (a room lit through its window), and a new
// seed every frame turns that noise into flicker. Each receiver takes the joint bilateral mean
// of the sky pass's demodulated light A L~(b) / pi over the (2R+1)^2 receivers around it:
//   w = exp(-|offset|^2 / (2 sigma^2)) * bilateral_match(...)   (sigma = R / 2 for the sky, R
//       for HVL's near field, push.sigma_per_radius; the match is
//       paper 002's eq. 11 with the upsample's sigma_z and normal exponent; for the near field,
//       push.world_sigma > 0, the match's depth offset is measured off the receiver's
//       tangent plane, bilateral_plane_match, and a gaussian of sigma world_sigma over the
//       receivers' world distance bounds the reach: issue 43, change 13)
// and sends kd times the mean towards the camera (kd from brdf_indirect_weights), so the
// albedo's texture is not blurred. R = 0 modulates only. Writes RGBA16F, a = 0, 0 on
// background. tests/sky.rs checks the filtered light against the path tracer.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"
#include "bilateral.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D recv_normal;
layout(set = 0, binding = 2, rgba8) readonly uniform image2D recv_albedo;
layout(set = 0, binding = 3, rgba8) readonly uniform image2D recv_material;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D sky_irradiance;
layout(set = 0, binding = 5, rgba16f) writeonly uniform image2D sky;

// shine::passes::sky::SkyFilterPush (48 bytes).
layout(push_constant) uniform Push {
    // xyz: camera position
    vec4 camera;
    // receiver buffer size
    uvec2 extent;
    // R: the filter's radius in receivers (0: no filter)
    uint radius;
    // sigma_z and n of the bilateral match
    float depth_sigma;
    float normal_power;
    // sigma of the gaussian over the radius R (the sky: 1/2)
    float sigma_per_radius;
    // sigma of a gaussian over the receivers' world distance, the match's depth offset then
    // measured off the receiver's tangent plane; 0: neither (the sky)
    float world_sigma;
    uint pad;
} push;

void main() {
    uvec2 xy = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(xy, push.extent))) {
        return;
    }
    ivec2 ixy = ivec2(xy);
    vec4 position = imageLoad(recv_position, ixy);
    vec3 n = imageLoad(recv_normal, ixy).xyz;
    if (!(position.w > 0.0) || dot(n, n) <= 0.0) {
        imageStore(sky, ixy, vec4(0.0));
        return;
    }
    n = normalize(n);
    int r = int(push.radius);
    float sigma = push.sigma_per_radius * float(r);
    float inv_two_sigma2 = r > 0 ? 0.5 / (sigma * sigma) : 0.0;
    ivec2 last = ivec2(push.extent) - 1;
    vec3 sum = vec3(0.0);
    float weight_sum = 0.0;
    for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
            ivec2 c = ixy + ivec2(dx, dy);
            if (any(lessThan(c, ivec2(0))) || any(greaterThan(c, last))) {
                continue;
            }
            vec4 pc = imageLoad(recv_position, c);
            if (!(pc.w > 0.0)) {
                continue;
            }
            vec3 nc = imageLoad(recv_normal, c).xyz;
            float w = exp(-float(dx * dx + dy * dy) * inv_two_sigma2);
            if (push.world_sigma > 0.0) {
                vec3 d = pc.xyz - position.xyz;
                w *= exp(-dot(d, d) / (2.0 * push.world_sigma * push.world_sigma))
                    * bilateral_plane_match(position.xyz, position.w, n, pc.xyz, nc,
                        push.depth_sigma, push.normal_power);
            } else {
                w *= bilateral_match(position.w, n, pc.w, nc, push.depth_sigma,
                    push.normal_power);
            }
            sum += w * imageLoad(sky_irradiance, c).rgb;
            weight_sum += w;
        }
    }
    vec3 light = weight_sum > 0.0 ? sum / weight_sum : imageLoad(sky_irradiance, ixy).rgb;
    vec3 albedo = imageLoad(recv_albedo, ixy).rgb;
    float metallic = imageLoad(recv_material, ixy).g;
    vec3 kd;
    vec3 ks;
    brdf_indirect_weights(albedo, metallic, dot(n, normalize(push.camera.xyz - position.xyz)), kd, ks);
    imageStore(sky, ixy, vec4(kd * light, 0.0));
}
