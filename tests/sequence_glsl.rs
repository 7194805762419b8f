//! `sobol_02` of `shaders/include/random.glsl` against `shine_sh::sequence::sobol_02` on the
//! same indices and digital shifts, bit for bit (`shaders/tests/sobol.comp` on the Vulkan
//! device): the AAF passes' sample directions.

mod common;

use shine::shaders;
use shine_sh::sequence::sobol_02;

#[test]
fn sobol_glsl_matches_shine_sh() {
    let device = common::device();
    // Every index of the first 1024 points (the AAF passes' counts) and a few large ones, each
    // with its own shift.
    let cases: Vec<[u32; 3]> = (0..1024u32)
        .chain([65_535, 1 << 20, u32::MAX])
        .map(|i| {
            let shift = i.wrapping_mul(0x9e37_79b9) ^ 0x85eb_ca6b;
            [i, shift, shift.rotate_left(13) ^ 0x2c1b_3c6d]
        })
        .collect();
    let bytes = common::run_cases(
        &device,
        &shaders::TESTS_SOBOL_COMP,
        bytemuck::cast_slice(&cases),
        (cases.len() * 8) as u64,
        cases.len() as u32,
    );
    let gpu: &[[f32; 2]] = bytemuck::cast_slice(&bytes);
    for (case, got) in cases.iter().zip(gpu) {
        let want = sobol_02(case[0], [case[1], case[2]]);
        assert_eq!(*got, want, "point {} with shift {:?}", case[0], &case[1..]);
    }
    common::assert_clean(&device);
}
