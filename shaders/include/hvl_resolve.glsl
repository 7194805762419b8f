// The constants and the disocclusion test of shaders/hvl_resolve.comp; Rust twin:
// shine::passes::hvl::resolve (RESOLVE_ALPHA, RESOLVE_DEPTH_TOLERANCE, RESOLVE_NORMAL_COS,
// same_surface), tied by tests/shader_constants.rs.
#ifndef HVL_RESOLVE_GLSL
#define HVL_RESOLVE_GLSL

// The gather's slice that shades the receivers `hvl_regather_mask` marked (alpha -1).
const uint HVL_REGATHER_SLICE = 5u;

// Weight of the fresh gather where a receiver is refreshed and its history is valid.
const float RESOLVE_ALPHA = 0.5;
// Largest relative difference of linear depth between a receiver and its history.
const float RESOLVE_DEPTH_TOLERANCE = 0.1;
// Smallest cosine between a receiver's normal and its history's.
const float RESOLVE_NORMAL_COS = 0.9;

// Whether history at linear depth `depth_then` with normal `n_then` shows the same surface as
// a receiver at `depth` with unit normal `n`.
bool resolve_same_surface(float depth, vec3 n, float depth_then, vec3 n_then) {
    return depth_then > 0.0 && abs(depth_then - depth) <= RESOLVE_DEPTH_TOLERANCE * depth
        && dot(n, n_then) >= RESOLVE_NORMAL_COS * length(n_then);
}

#endif
