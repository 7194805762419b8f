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

#endif
