// receivers: the G-buffer at 1/s resolution (docs/frame.md "Receiver buffer", paper 002 §4.2).
//
// Each receiver pixel copies ONE G-buffer sample of its s×s block, so its position, normal,
// albedo and material stay consistent: the valid sample (w > 0) with the smallest linear depth,
// the first in row-major order on ties; the block's first sample when none is valid.
// Blocks on the right and bottom edges of a size not divisible by s are clipped to the image.
// CPU reference: `shine::passes::receivers::receiver_samples`.
#version 460

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D gb_normal;
layout(set = 0, binding = 2, rgba8) readonly uniform image2D gb_albedo;
layout(set = 0, binding = 3, rgba8) readonly uniform image2D gb_material;

layout(set = 0, binding = 4, rgba32f) uniform image2D recv_position;
layout(set = 0, binding = 5, rgba16f) uniform image2D recv_normal;
layout(set = 0, binding = 6, rgba8) uniform image2D recv_albedo;
layout(set = 0, binding = 7, rgba8) uniform image2D recv_material;

layout(push_constant) uniform Push {
    // Full-resolution extent W×H.
    uint width;
    uint height;
    // Receiver extent ceil(W/s)×ceil(H/s).
    uint recv_width;
    uint recv_height;
    // Block size s ∈ {1, 2, 4}.
    uint scale;
} push;

void main() {
    uvec2 r = gl_GlobalInvocationID.xy;
    if (r.x >= push.recv_width || r.y >= push.recv_height) {
        return;
    }
    uvec2 origin = r * push.scale;
    uvec2 end = min(origin + uvec2(push.scale), uvec2(push.width, push.height));
    ivec2 chosen = ivec2(origin);
    vec4 chosen_position = imageLoad(gb_position, chosen);
    bool found = false;
    for (uint y = origin.y; y < end.y; y++) {
        for (uint x = origin.x; x < end.x; x++) {
            ivec2 p = ivec2(x, y);
            vec4 position = imageLoad(gb_position, p);
            if (position.w > 0.0 && (!found || position.w < chosen_position.w)) {
                found = true;
                chosen = p;
                chosen_position = position;
            }
        }
    }
    ivec2 out_p = ivec2(r);
    imageStore(recv_position, out_p, chosen_position);
    imageStore(recv_normal, out_p, imageLoad(gb_normal, chosen));
    imageStore(recv_albedo, out_p, imageLoad(gb_albedo, chosen));
    imageStore(recv_material, out_p, imageLoad(gb_material, chosen));
}
