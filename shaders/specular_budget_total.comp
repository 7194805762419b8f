// specular_budget_total (issue 47, item 2; src/passes/specular.rs): the frame's total claim on
// the specular rays and its traced pixels, summed over specular_budget.comp's tiles in a fixed
// order (thread t takes tiles t, t + 64, …; thread 0 sums the 64). Writes `budget` (claims,
// traced pixels), which specular.comp divides its rays by.
#version 460

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer BudgetTiles {
    vec2 t[];
} budget_tiles;

layout(set = 0, binding = 1, std430) buffer Budget {
    vec2 total;
} budget;

// A bare u32 from shine::passes::specular (the tile count).
layout(push_constant) uniform Push {
    // tiles of specular_budget
    uint tiles;
} push;

shared vec2 sums[64];

void main() {
    uint t = gl_LocalInvocationIndex;
    vec2 sum = vec2(0.0);
    for (uint i = t; i < push.tiles; i += 64u) {
        sum += budget_tiles.t[i];
    }
    sums[t] = sum;
    barrier();
    if (t == 0u) {
        vec2 total = vec2(0.0);
        for (uint i = 0u; i < 64u; ++i) {
            total += sums[i];
        }
        budget.total = total;
    }
}
