//! Low-discrepancy sample points of the Monte-Carlo passes: the first two dimensions of the
//! Sobol sequence, a (0, 2)-sequence in base 2. Every prefix of `2^k` points puts one point in
//! each elementary interval of area `2^-k` (for 16 points: a 4 × 4 grid, 2 × 8, 8 × 2, 1 × 16,
//! 16 × 1), so the first `2^k` samples of a pixel, and every aligned block of `2^k` after them,
//! are stratified, and a second pass that continues the sequence keeps the first pass's strata
//! (counts between powers of two are stratified at the next coarser level). A random digital shift (XOR of
//! the bits) per pixel decorrelates pixels and keeps the property. GLSL twin: `sobol_02` in
//! `shaders/include/random.glsl` (tied by tests/sequence_glsl.rs).

/// The bits of point `i`: dimension 1 is the base-2 radical inverse (the bits of `i`
/// reversed); dimension 2's generator matrix is the Pascal matrix mod 2, whose columns are
/// `v_1 = 2^31`, `v_{k+1} = v_k ^ (v_k >> 1)`.
pub fn sobol_02_bits(i: u32) -> [u32; 2] {
    let (mut k, mut v, mut y) = (i, 1u32 << 31, 0u32);
    while k != 0 {
        if k & 1 != 0 {
            y ^= v;
        }
        k >>= 1;
        v ^= v >> 1;
    }
    [i.reverse_bits(), y]
}

/// Point `i` in `[0, 1)²` after the digital shift `shift`, with 24 bits per coordinate (exact
/// in `f32`).
pub fn sobol_02(i: u32, shift: [u32; 2]) -> [f32; 2] {
    let bits = sobol_02_bits(i);
    [0, 1].map(|d| ((bits[d] ^ shift[d]) >> 8) as f32 / (1u32 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_power_of_two_prefix_is_a_0_2_net() {
        for shift in [[0, 0], [0x9e37_79b9, 0x85eb_ca6b], [u32::MAX, 12345]] {
            for k in 0..=8u32 {
                let points: Vec<[f32; 2]> = (0..1u32 << k).map(|i| sobol_02(i, shift)).collect();
                for a in 0..=k {
                    let (nx, ny) = (1usize << a, 1usize << (k - a));
                    let mut cells = vec![0u32; nx * ny];
                    for p in &points {
                        let (x, y) = ((p[0] * nx as f32) as usize, (p[1] * ny as f32) as usize);
                        cells[y * nx + x] += 1;
                    }
                    assert!(
                        cells.iter().all(|&c| c == 1),
                        "shift {shift:?}: {} points in {nx} x {ny} cells: {cells:?}",
                        1 << k
                    );
                }
            }
        }
    }

    #[test]
    fn the_first_points_are_sobols() {
        // Sobol's sequence, dimensions 1 and 2: (0, 0), (1/2, 1/2), (1/4, 3/4), (3/4, 1/4),
        // (1/8, 5/8), (5/8, 1/8), …
        let want = [
            [0.0, 0.0],
            [0.5, 0.5],
            [0.25, 0.75],
            [0.75, 0.25],
            [0.125, 0.625],
            [0.625, 0.125],
        ];
        for (i, w) in want.iter().enumerate() {
            assert_eq!(sobol_02(i as u32, [0, 0]), *w, "point {i}");
        }
    }
}
