// Random numbers of the Monte-Carlo passes: a PCG hash (Jarzynski & Olano 2020) and a
// per-invocation generator. Seed rng_state before calling rand().
#ifndef RANDOM_GLSL
#define RANDOM_GLSL

uint rng_state;

// PCG hash (Jarzynski & Olano 2020).
uint pcg(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A uniform number in [0, 1) with 24 random bits.
float rand() {
    rng_state = pcg(rng_state);
    return float(rng_state >> 8) * (1.0 / 16777216.0);
}

// Point i of the first two dimensions of the Sobol sequence, a (0, 2)-sequence in base 2: every
// prefix of 2^k points puts one point in each of the 2^k elementary intervals of area 2^-k (for
// 16 points: a 4 x 4 grid, 2 x 8, 8 x 2, ...), so the first 2^k samples of a pixel, and every
// aligned block of 2^k after them, are stratified. Dimension 1 is the base-2 radical inverse; dimension 2's generator matrix is
// the Pascal matrix mod 2 (v_{k+1} = v_k ^ (v_k >> 1)). `shift`: a random digital shift (XOR),
// which keeps the stratification. 24 bits per coordinate. Rust twin:
// shine_sh::sequence::sobol_02 (tests/sequence_glsl.rs).
vec2 sobol_02(uint i, uvec2 shift) {
    uint y = 0u;
    for (uint k = i, v = 1u << 31; k != 0u; k >>= 1u, v ^= v >> 1u) {
        if ((k & 1u) != 0u) {
            y ^= v;
        }
    }
    uvec2 bits = uvec2(bitfieldReverse(i), y) ^ shift;
    return vec2(bits >> 8u) * (1.0 / 16777216.0);
}

#endif
