// GI amortised over frames (paper 001): which pixel a thread shades in a slice, and the
// constants and the disocclusion test of shaders/amortise.comp; Rust twin:
// shine::passes::amortise (REGATHER_SLICE, RESOLVE_ALPHA, RESOLVE_DEPTH_TOLERANCE,
// RESOLVE_NORMAL_COS, RESOLVE_CHANGE_LIMIT, RECORD_BLOCK, same_surface, changed, slice_threads), tied by
// tests/shader_constants.rs and the CPU twins of tests/amortise.rs.
#ifndef AMORTISE_GLSL
#define AMORTISE_GLSL

// The slice that shades only the pixels `*_regather_mask` marked (alpha -1 in the light).
const uint AMORTISE_REGATHER_SLICE = 5u;

// Weight of the fresh light where a pixel is refreshed and its history is valid.
const float RESOLVE_ALPHA = 0.5;
// Largest relative difference of linear depth between a pixel and its history.
const float RESOLVE_DEPTH_TOLERANCE = 0.1;
// Smallest cosine between a pixel's normal and its history's.
const float RESOLVE_NORMAL_COS = 0.9;
// Largest change of a cell's refreshed pixel (or a block's summed records), relative to the
// larger of its value now and in its history, before the cell's other pixels take the new
// light the same frame (a light or an object moved: paper 001's priority refresh of what it
// affects): the refreshed pixel's where they show its surface, their own shaded again
// otherwise, and a block of records regathered.
const float RESOLVE_CHANGE_LIMIT = 0.5;
// Side of the square block of pixels whose refreshed records' signals the records' change test
// sums (4×4 cells).
const int AMORTISE_RECORD_BLOCK = 8;

// Where the refreshed pixel of every 2×2 cell is in slice 1 + k: (k & 1, k >> 1).
ivec2 amortise_offset(uint slice) {
    uint k = slice - 1u;
    return ivec2(k & 1u, k >> 1u);
}

// The pixel thread `id` shades in `slice`: itself for 0 (every pixel) and the regather slice,
// the pixel at offset (k & 1, k >> 1) of cell `id` for slice 1 + k (a quarter of the threads,
// `slice_threads`).
ivec2 amortise_pixel(uvec2 id, uint slice) {
    if (slice == 0u || slice == AMORTISE_REGATHER_SLICE) {
        return ivec2(id);
    }
    return 2 * ivec2(id) + amortise_offset(slice);
}

// Whether pixel p is the refreshed one of its cell in slice 1 + k (true for slice 0).
bool amortise_refreshed(ivec2 p, uint slice) {
    if (slice == 0u) {
        return true;
    }
    return (p & 1) == amortise_offset(slice);
}

// Whether history at linear depth `depth_then` with normal `n_then` shows the same surface as
// a pixel at `depth` with unit normal `n`.
bool resolve_same_surface(float depth, vec3 n, float depth_then, vec3 n_then) {
    return depth_then > 0.0 && abs(depth_then - depth) <= RESOLVE_DEPTH_TOLERANCE * depth
        && dot(n, n_then) >= RESOLVE_NORMAL_COS * length(n_then);
}

// Whether light `now` differs from `then`, in any channel, by more than RESOLVE_CHANGE_LIMIT
// of the brightest channel of either (a dim channel's noise does not count).
bool amortise_changed(vec3 now, vec3 then) {
    vec3 big = max(abs(now), abs(then));
    vec3 d = abs(now - then);
    return max(d.r, max(d.g, d.b)) > RESOLVE_CHANGE_LIMIT * max(big.r, max(big.g, big.b));
}

#endif
