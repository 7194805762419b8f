// Texels of one grid under the centres of another's (a GI context's internal resolution
// against the display). Rust twin: shine::passes::upsample::texel_under_centre.
#ifndef GRID_GLSL
#define GRID_GLSL

// The texel of a `to`-sized grid under the centre of texel i of a `from`-sized grid over the
// same image: floor((i + 0.5) · to / from), in integers (no rounding at the exact ties of a
// 2× or 4× step).
uvec2 texel_under_centre(uvec2 i, uvec2 from, uvec2 to) {
    return ((2u * i + 1u) * to) / (2u * from);
}

#endif
