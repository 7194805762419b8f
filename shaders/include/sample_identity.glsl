// Samples with identities (issue 43): the budget split between lights and the interleaved set a
// sample belongs to (the points each light owns in its RSM are sobol_02 of random.glsl). CPU
// twin: shine::reference::hvl_flux (same names without the hvl_flux_ / igi_ prefix); the GPU
// twin tests in tests/hvl.rs and tests/igi.rs tie them. Integer digit arithmetic and correctly
// rounded products only, so both sides agree bit for bit.
#ifndef SAMPLE_IDENTITY_GLSL
#define SAMPLE_IDENTITY_GLSL

// Most sets of an interleaving pattern, 8 x 8 (shine::passes::igi::SETS_MAX).
const uint IGI_SETS_MAX = 64u;

// Base-5 digits of the set key (9 digits: 5^9 times the most sets, 64, fits a uint).
const uint IGI_SET_DIGITS = 9u;
const uint IGI_SET_SCALE = 1953125u;

// The base-b radical inverse of j to `digits` digits, as the integer numerator over b^digits.
uint radical_inverse_digits(uint j, uint b, uint digits) {
    uint r = 0u;
    for (uint d = 0u; d < digits; ++d) {
        r = r * b + j % b;
        j /= b;
    }
    return r;
}

// The digital shift of the flux samples' Sobol points (shine::reference::hvl_flux::SOBOL_SHIFT):
// a half in both dimensions, so a light's first sample sits at the middle of its flux.
const uint HVL_FLUX_SOBOL_SHIFT = 0x80000000u;

// M' = M - (N - 1) samples split between N lights (at least 1), so that the N rounded-up
// counts sum to at most M.
uint hvl_flux_budget(uint count, uint lights) {
    return count > lights ? count - (lights - 1u) : 1u;
}

// n_k = ceil(M' Phi_k / Phi), decided by products: the least n with n Phi >= M' Phi_k, at most
// M'; 0 unless 0 < Phi_k and Phi is finite (no loop can run away on extreme flux).
uint hvl_flux_light_count(uint budget, float light_total, float total) {
    float goal = float(budget) * light_total;
    if (!(light_total > 0.0) || !(total > 0.0) || isinf(total) || isinf(goal)) {
        return 0u;
    }
    uint n = min(uint(ceil(goal / total)), budget);
    while (n > 0u && float(n - 1u) * total >= goal) {
        --n;
    }
    while (n < budget && float(n) * total < goal) {
        ++n;
    }
    return n;
}

// The interleaved set (of `sets`) of sample j: floor(phi_5(j) sets), so that each light's
// samples spread evenly over the sets and a sample keeps its set when the records reorder.
uint igi_sample_set(uint j, uint sets) {
    return radical_inverse_digits(j, 5u, IGI_SET_DIGITS) * sets / IGI_SET_SCALE;
}

#endif
