//! Benchmarks: basis evaluation, cap projection (ZH eq. 14 + rotation eq. 15) and the HYB
//! exponential at 3, 5 and 9 bands; the tables built when a renderer starts: a GGX BRDF table
//! (the HVL gather's, default sampling) and the triple-product tensor, at 3 and 5 bands.
//!
//! `cargo bench -p shine-sh --bench sh`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::Vec3;
use shine_sh::basis::eval_basis_into;
use shine_sh::brdf_table::{BrdfModel, BrdfTable};
use shine_sh::exp_log::ShExp;
use shine_sh::product::TripleProduct;
use shine_sh::zonal::{cap_sh, sphere_half_angle};

fn benches(c: &mut Criterion) {
    let dir = Vec3::new(0.3, -0.5, 0.8).normalize();
    let mut group = c.benchmark_group("sh");
    for bands in [3usize, 5, 9] {
        let mut out = vec![0.0f32; bands * bands];
        group.bench_with_input(BenchmarkId::new("eval_basis", bands), &bands, |b, &n| {
            b.iter(|| eval_basis_into(black_box(dir), n, &mut out))
        });
        let half = sphere_half_angle(3.0, 0.7).unwrap_or(0.2);
        group.bench_with_input(
            BenchmarkId::new("cap_projection", bands),
            &bands,
            |b, &n| b.iter(|| cap_sh(black_box(dir), black_box(half), n)),
        );
        let Ok(sx) = ShExp::new(bands) else {
            continue;
        };
        // summed log-visibility of three blockers
        let mut f = vec![0.0f32; bands * bands];
        for (d, a) in [
            (dir, 0.3f32),
            (Vec3::Z, 0.5),
            (Vec3::new(0.5, 0.5, 0.7).normalize(), 0.4),
        ] {
            let Ok(v) = cap_sh(d, a, bands) else { continue };
            let mut vis: Vec<f32> = v.iter().map(|x| -x).collect();
            vis[0] += (4.0 * std::f32::consts::PI).sqrt();
            if let Ok(l) = sx.log(&vis) {
                f.iter_mut().zip(&l).for_each(|(s, x)| *s += x);
            }
        }
        group.bench_with_input(BenchmarkId::new("exp_hyb", bands), &bands, |b, _| {
            b.iter(|| sx.exp_hyb(black_box(&f)))
        });
    }
    group.finish();
    let mut tables = c.benchmark_group("tables");
    tables.sample_size(10);
    for bands in [3usize, 5] {
        let ggx = BrdfModel::Ggx {
            alpha: 0.25,
            ior: 1.5,
        };
        tables.bench_with_input(
            BenchmarkId::new("brdf_table_ggx", bands),
            &bands,
            |b, &n| b.iter(|| BrdfTable::build(black_box(ggx), n)),
        );
        tables.bench_with_input(
            BenchmarkId::new("triple_product", bands),
            &bands,
            |b, &n| b.iter(|| TripleProduct::new(black_box(n))),
        );
    }
    tables.finish();
}

criterion_group!(sh, benches);
criterion_main!(sh);
