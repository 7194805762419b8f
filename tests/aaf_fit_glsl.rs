//! `AafFit` of `shaders/include/aaf.glsl` (the AAF filter's local fit: its value and its
//! precision) against `shine_sh::aaf::LocalFit` on the same neighbours
//! (`shaders/tests/aaf_fit.comp` on the Vulkan device).

mod common;

use shine::shaders;
use shine_sh::aaf::LocalFit;

/// Most neighbours of a case (`AAF_FIT_NEIGHBOURS_MAX` of the shader).
const NEIGHBOURS_MAX: usize = 8;
/// Words of a case (`AAF_FIT_CASE_WORDS`): degree, count, then u, y, p per neighbour.
const CASE_WORDS: usize = 2 + 3 * NEIGHBOURS_MAX;

/// A fit's inputs: degree and (u, y, p) per neighbour.
struct Case {
    degree: u32,
    neighbours: Vec<[f32; 3]>,
}

#[test]
fn aaf_fit_glsl_matches_shine_sh() {
    let device = common::device();
    // Every degree over two-sided, one-sided and sparse neighbourhoods of unequal precision.
    let mut cases = Vec::new();
    for c in 0..96u32 {
        let count = 1 + (c as usize % NEIGHBOURS_MAX);
        let one_sided = c % 5 == 0;
        let neighbours = (0..count as u32)
            .map(|k| {
                let h = |s: u32| common::hash01(c * 97 + k * 13 + s);
                let u = if one_sided {
                    2.0 * h(0)
                } else {
                    4.0 * h(0) - 2.0
                };
                [u, 1.0 + 3.0 * h(1) + 0.5 * u * u, 0.2 + 3.0 * h(2)]
            })
            .collect();
        cases.push(Case {
            degree: c % 3,
            neighbours,
        });
    }
    let words: Vec<u32> = cases
        .iter()
        .flat_map(|case| {
            let mut w = vec![0u32; CASE_WORDS];
            w[0] = case.degree;
            w[1] = case.neighbours.len() as u32;
            for (k, n) in case.neighbours.iter().enumerate() {
                for (j, x) in n.iter().enumerate() {
                    w[2 + 3 * k + j] = x.to_bits();
                }
            }
            w
        })
        .collect();
    let bytes = common::run_cases(
        &device,
        &shaders::TESTS_AAF_FIT_COMP,
        bytemuck::cast_slice(&words),
        (cases.len() * 8) as u64,
        cases.len() as u32,
    );
    let gpu: &[[f32; 2]] = bytemuck::cast_slice(&bytes);
    for (i, (case, got)) in cases.iter().zip(gpu).enumerate() {
        let mut fit = LocalFit::<1>::default();
        for &[u, y, p] in &case.neighbours {
            fit.add(u, [y], p);
        }
        let want = [
            fit.value(case.degree).unwrap()[0],
            fit.precision(case.degree).unwrap(),
        ];
        for (name, g, w) in [("value", got[0], want[0]), ("precision", got[1], want[1])] {
            assert!(
                (g - w).abs() <= 1e-3 * w.abs().max(1.0),
                "case {i} (degree {}, {} neighbours): {name} {g} against {w}",
                case.degree,
                case.neighbours.len()
            );
        }
    }
    common::assert_clean(&device);
}
