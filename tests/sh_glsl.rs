//! `shaders/include/sh.glsl` against shine-sh on the same inputs: every per-pixel function the
//! GPU passes use (basis, cap ZH, ZH rotation, dot, evaluation, kernels, convolution, sinc
//! window, HVL geometric factor and cap terms, and for ≤ 4 bands the SH product and HYB exponential), for
//! 2, 3, 4 and 6 bands (the basis alone is checked to 8 bands by tests/sh_eval.rs), run by `shaders/tests/sh_glsl.comp` on the Vulkan device.
//!
//! Case layout (floats): dir.xyz, cos a, Phong n, window width, HVL radius, HVL half-angle,
//! HVL normal.xyz, HVL distance, receiver normal.xyz, 0, f[n²], g[n²]. Results, in order:
//! basis(dir), cap ZH, cap SH around dir, dot(f, g), f at dir, clamped-cosine ZH, Phong ZH,
//! convolve(f, Phong), sinc-windowed cap ZH, HVL geometric factor, HVL cap half-angle, the
//! basis at m ≥ 0 (sh_basis_even), HVL cap terms (cos a, H), then for ≤ 4 bands product(f, g)
//! and exp_hyb(f).

mod common;

use glam::Vec3;
use shine::shaders;
use shine_sh::{
    basis, dot, exp_log::ShExp, hvl, kernels, kernels::Window, product::TripleProduct, zonal,
};

/// Deterministic xorshift so failures reproduce.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }

    fn direction(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if (0.05..=1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }
}

struct Case {
    dir: Vec3,
    a: f32,
    phong_n: f32,
    window: f32,
    radius: f32,
    half_angle: f32,
    hvl_normal: Vec3,
    /// Receiver-to-HVL-centre distance of the cap half-angle (inside and outside the HVL).
    hvl_distance: f32,
    receiver_normal: Vec3,
    f: Vec<f32>,
    g: Vec<f32>,
}

impl Case {
    fn floats(&self) -> Vec<f32> {
        let mut v = vec![
            self.dir.x,
            self.dir.y,
            self.dir.z,
            self.a.cos(),
            self.phong_n,
            self.window,
            self.radius,
            self.half_angle,
            self.hvl_normal.x,
            self.hvl_normal.y,
            self.hvl_normal.z,
            self.hvl_distance,
            self.receiver_normal.x,
            self.receiver_normal.y,
            self.receiver_normal.z,
            0.0,
        ];
        v.extend(&self.f);
        v.extend(&self.g);
        v
    }
}

/// Visibility of one spherical blocker seen as a cap: 1 − cap indicator, projected.
fn blocker_visibility(dir: Vec3, a: f32, bands: usize) -> Vec<f32> {
    let mut v = zonal::cap_sh(dir, a, bands)
        .expect("cap")
        .iter()
        .map(|c| -c)
        .collect::<Vec<_>>();
    v[0] += (4.0 * std::f32::consts::PI).sqrt();
    v
}

fn cases(bands: usize, rng: &mut Rng) -> Vec<Case> {
    let exp = ShExp::new(bands).expect("ShExp");
    (0..48)
        .map(|_| {
            // f: the summed log-visibility of two blockers, as paper 002 accumulates it.
            let mut f = vec![0.0; bands * bands];
            for _ in 0..2 {
                let log = exp
                    .log(&blocker_visibility(
                        rng.direction(),
                        rng.range(0.1, 0.6),
                        bands,
                    ))
                    .expect("log");
                f.iter_mut().zip(log).for_each(|(a, b)| *a += b);
            }
            let g = blocker_visibility(rng.direction(), rng.range(0.2, 1.2), bands);
            Case {
                dir: rng.direction() * rng.range(0.5, 3.0),
                a: rng.range(0.05, 3.0),
                phong_n: rng.range(0.0, 64.0),
                window: rng.range(1.0, 2.0 * bands as f32),
                radius: rng.range(0.05, 1.0),
                half_angle: rng.range(0.0, 1.2),
                hvl_normal: rng.direction(),
                hvl_distance: rng.range(0.0, 2.0),
                receiver_normal: rng.direction(),
                f,
                g,
            }
        })
        .collect()
}

/// What shine-sh computes for one case, in the shader's output order, with the tolerance of
/// each value (absolute, on values of order 1).
fn expected(
    case: &Case,
    bands: usize,
    exp: &ShExp,
    tensor: &TripleProduct,
) -> Vec<(f32, f32, &'static str)> {
    const F32: f32 = 2e-5;
    let mut out = Vec::new();
    let mut put = |values: &[f32], tol: f32, what: &'static str| {
        out.extend(values.iter().map(|&v| (v, tol * (1.0 + v.abs()), what)));
    };
    put(
        &basis::eval_basis(case.dir.normalize(), bands).expect("basis"),
        F32,
        "basis",
    );
    let mut zh = zonal::cap_zh(case.a, bands).expect("cap zh");
    put(&zh, F32, "cap zh");
    put(
        &zonal::cap_sh(case.dir, case.a, bands).expect("cap sh"),
        F32,
        "cap sh",
    );
    put(&[dot(&case.f, &case.g).expect("dot")], 1e-4, "dot");
    put(
        &[basis::evaluate(&case.f, case.dir).expect("evaluate")],
        1e-4,
        "evaluate",
    );
    put(
        &kernels::clamped_cosine_zh(bands).expect("cosine"),
        F32,
        "clamped cosine",
    );
    let phong = kernels::phong_zh(case.phong_n, bands).expect("phong");
    put(&phong, 1e-4, "phong zh");
    put(
        &kernels::convolve(&case.f, &phong).expect("convolve"),
        1e-4,
        "convolve",
    );
    Window::Sinc { width: case.window }
        .apply_zh(&mut zh)
        .expect("window");
    put(&zh, F32, "sinc window");
    let g = hvl::geometric_factor(
        case.dir,
        case.hvl_normal,
        case.receiver_normal,
        case.radius,
        case.half_angle,
    )
    .expect("geometric factor");
    // f32 acos in the shader: ~2e-4 relative (measured), so 1e-3.
    put(&[g], 1e-3, "hvl geometric factor");
    let a = hvl::cap_half_angle(case.hvl_distance, case.radius).expect("cap half-angle");
    // f32 asin in the shader: 1.4e-4 measured, so 1e-3 as for the geometric factor.
    put(&[a], 1e-3, "hvl cap half-angle");
    let full = basis::eval_basis(case.dir.normalize(), bands).expect("basis");
    let even: Vec<f32> = (0..bands)
        .flat_map(|l| (0..=l).map(move |m| l * l + l + m))
        .map(|i| full[i])
        .collect();
    put(&even, F32, "basis m ≥ 0");
    let cos_r = case.receiver_normal.normalize().dot(case.dir.normalize());
    let (cos_a, h) = hvl::cap_terms(case.hvl_distance, case.radius, cos_r).expect("cap terms");
    // f32 asin/acos across the horizon, as for the geometric factor.
    put(&[cos_a, h], 1e-3, "hvl cap terms");
    if bands <= 4 {
        put(
            &tensor.product(&case.f, &case.g).expect("product"),
            1e-4,
            "product",
        );
        put(&exp.exp_hyb(&case.f).expect("exp hyb"), 1e-4, "exp hyb");
    }
    out
}

fn run_bands(
    device: &shine::gpu::Device,
    shader: &'static shine::gpu::ShaderDesc,
    bands: usize,
) -> f32 {
    let mut rng = Rng(0x5eed_0000 + bands as u64);
    let cases = cases(bands, &mut rng);
    let exp = ShExp::new(bands).expect("ShExp");
    let tensor = TripleProduct::new(bands).expect("tensor");
    let expected: Vec<_> = cases
        .iter()
        .map(|c| expected(c, bands, &exp, &tensor))
        .collect();
    let stride = expected[0].len();
    let input: Vec<f32> = cases.iter().flat_map(Case::floats).collect();

    let bytes = common::run_cases(
        device,
        shader,
        bytemuck::cast_slice(&input),
        (cases.len() * stride * 4) as u64,
        cases.len() as u32,
    );
    let gpu: &[f32] = bytemuck::cast_slice(&bytes);

    let mut worst = 0.0f32;
    for (i, want) in expected.iter().enumerate() {
        for (k, &(value, tol, what)) in want.iter().enumerate() {
            let got = gpu[i * stride + k];
            let error = (got - value).abs();
            worst = worst.max(error / (1.0 + value.abs()));
            assert!(
                error <= tol,
                "{bands} bands, case {i}, {what} (output {k}): GLSL {got}, shine-sh {value}, |Δ| {error:.2e} > {tol:.2e}"
            );
        }
    }
    worst
}

#[test]
fn sh_glsl_matches_shine_sh() {
    let device = common::device();
    for (shader, bands) in [
        (&shaders::TESTS_SH_GLSL_COMP_BANDS2, 2),
        (&shaders::TESTS_SH_GLSL_COMP_BANDS3, 3),
        (&shaders::TESTS_SH_GLSL_COMP_BANDS4, 4),
        (&shaders::TESTS_SH_GLSL_COMP_BANDS6, 6),
    ] {
        let worst = run_bands(&device, shader, bands);
        eprintln!("{bands} bands: worst relative |GLSL - shine-sh| = {worst:.2e}");
    }
    common::assert_clean(&device);
}
