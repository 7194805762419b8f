//! `sh_eval.comp` on the GPU against a CPU evaluation of the real SH basis (docs/architecture.md, "Conventions"), for
//! bands 1 to 8, with the validation layer reporting nothing.

mod common;

use shine::shaders;

/// Directions covering the sphere (Fibonacci lattice) plus the six axes and the poles' sides.
fn directions() -> Vec<[f32; 4]> {
    let mut dirs = vec![
        [1.0, 0.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, -1.0, 0.0],
    ];
    let n = 250;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    for i in 0..n {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * i as f64;
        dirs.push([
            (r * phi.cos()) as f32,
            (r * phi.sin()) as f32,
            z as f32,
            0.0,
        ]);
    }
    dirs
}

fn factorial(n: u32) -> f64 {
    (1..=n).map(f64::from).product()
}

/// Associated Legendre P(l, m)(x) with the Condon–Shortley phase, by the explicit sum
/// (Rodrigues' formula expanded): independent of the recurrence the shader uses.
fn legendre(l: u32, m: u32, x: f64) -> f64 {
    let mut sum = 0.0;
    for k in 0..=((l - m) / 2) {
        let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        let num = factorial(2 * l - 2 * k);
        let den = factorial(k) * factorial(l - k) * factorial(l - m - 2 * k);
        sum += sign * num / den * x.powi((l - m - 2 * k) as i32);
    }
    let cs = if m.is_multiple_of(2) { 1.0 } else { -1.0 };
    cs * (1.0 - x * x).powf(m as f64 / 2.0) * sum / 2f64.powi(l as i32)
}

/// Real SH basis Y(l, m) at a unit direction, via spherical angles.
fn sh_reference(l: u32, m: i32, d: [f64; 3]) -> f64 {
    let theta = d[2].clamp(-1.0, 1.0).acos();
    let phi = d[1].atan2(d[0]);
    let am = m.unsigned_abs();
    let k = ((2 * l + 1) as f64 / (4.0 * std::f64::consts::PI) * factorial(l - am)
        / factorial(l + am))
    .sqrt();
    let p = legendre(l, am, theta.cos());
    match m.signum() {
        0 => k * p,
        1 => 2f64.sqrt() * k * (am as f64 * phi).cos() * p,
        _ => 2f64.sqrt() * k * (am as f64 * phi).sin() * p,
    }
}

#[test]
fn sh_eval_matches_cpu_basis_for_bands_1_to_8() {
    let device = common::device();
    let dirs = directions();
    let variants = [
        &shaders::SH_EVAL_COMP_BANDS1,
        &shaders::SH_EVAL_COMP_BANDS2,
        &shaders::SH_EVAL_COMP_BANDS3,
        &shaders::SH_EVAL_COMP_BANDS4,
        &shaders::SH_EVAL_COMP_BANDS5,
        &shaders::SH_EVAL_COMP_BANDS6,
        &shaders::SH_EVAL_COMP_BANDS7,
        &shaders::SH_EVAL_COMP_BANDS8,
    ];
    let mut worst = 0.0f64;
    for (index, shader) in variants.into_iter().enumerate() {
        let bands = index as u32 + 1;
        let coeffs = (bands * bands) as usize;
        let gpu = common::sh_eval(&device, shader, &dirs, coeffs);
        for (i, d) in dirs.iter().enumerate() {
            let d64 = [d[0] as f64, d[1] as f64, d[2] as f64];
            for l in 0..bands {
                for m in -(l as i32)..=(l as i32) {
                    let k = (l * l) as i32 + l as i32 + m;
                    let expected = sh_reference(l, m, d64);
                    let got = f64::from(gpu[i * coeffs + k as usize]);
                    let error = (got - expected).abs();
                    worst = worst.max(error);
                    // f32 tolerance: the recurrence loses a few ulps per band.
                    assert!(
                        error <= 2e-5 + 1e-5 * expected.abs(),
                        "bands {bands}, direction {d:?}, Y({l},{m}): GPU {got}, CPU {expected}"
                    );
                }
            }
        }
    }
    eprintln!("worst |GPU - CPU| over bands 1..8: {worst:.3e}");
    common::assert_clean(&device);
}

#[test]
fn condon_shortley_phase_on_the_gpu() {
    // ANCHORS pitfall: with our convention a delta at +x projects to a negative coefficient 3.
    let device = common::device();
    let dirs = [
        [1.0f32, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ];
    let y = common::sh_eval(&device, &shaders::SH_EVAL_COMP_BANDS2, &dirs, 4);
    let c1 = 0.488_602_5_f32;
    let expect = |got: f32, want: f32| assert!((got - want).abs() < 1e-6, "{got} vs {want}");
    expect(y[3], -c1); // +x: Y(1,1) = -c1 x
    expect(y[4 + 1], -c1); // +y: Y(1,-1) = -c1 y
    expect(y[8 + 2], c1); // +z: Y(1,0) = c1 z
    expect(y[0], 0.282_094_8);
    common::assert_clean(&device);
}
