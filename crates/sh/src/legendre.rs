//! Legendre polynomials `P_l(x)` by the three-term (Bonnet) recurrence.
//!
//! `(l+1) P_{l+1}(x) = (2l+1) x P_l(x) - l P_{l-1}(x)`; stable for `|x| ≤ 1` at any degree and
//! free of factorials. Paper 003 eq. 14 evaluates the cap ZH from these values.

/// All Legendre polynomials `P_0(x) ..= P_{out.len()-1}(x)` in `f64`, written into `out`.
pub fn legendre_all(x: f64, out: &mut [f64]) {
    if out.is_empty() {
        return;
    }
    out[0] = 1.0;
    if out.len() > 1 {
        out[1] = x;
    }
    for l in 1..out.len().saturating_sub(1) {
        let lf = l as f64;
        out[l + 1] = ((2.0 * lf + 1.0) * x * out[l] - lf * out[l - 1]) / (lf + 1.0);
    }
}

/// The single Legendre polynomial `P_l(x)` in `f64`.
pub fn legendre(l: usize, x: f64) -> f64 {
    let (mut p0, mut p1) = (1.0, x);
    if l == 0 {
        return p0;
    }
    for k in 1..l {
        let kf = k as f64;
        let p2 = ((2.0 * kf + 1.0) * x * p1 - kf * p0) / (kf + 1.0);
        p0 = p1;
        p1 = p2;
    }
    p1
}

/// `P_0 ..= P_{n-1}` as polynomials: row `l` holds the coefficients of `x^0 ..= x^{n-1}` in
/// `P_l(x)`, by the recurrence of [`legendre_all`] on coefficient rows.
pub fn legendre_monomials(n: usize) -> Vec<Vec<f64>> {
    let mut rows = vec![vec![0.0; n]; n];
    for l in 0..n {
        if l == 0 {
            rows[0][0] = 1.0;
            continue;
        }
        if l == 1 {
            rows[1][1] = 1.0;
            continue;
        }
        let k = (l - 1) as f64;
        for i in 0..n {
            let shifted = if i > 0 { rows[l - 1][i - 1] } else { 0.0 };
            rows[l][i] = ((2.0 * k + 1.0) * shifted - k * rows[l - 2][i]) / (k + 1.0);
        }
    }
    rows
}

/// `∫_{x}^{1} P_l(t) dt = (P_{l-1}(x) - P_{l+1}(x)) / (2l+1)` for `l ≥ 1`, and `1 - x` for `l = 0`.
///
/// Paper 003 eq. 13 writes the same integral as `∫_0^a P_l(cos θ) sin θ dθ` with `x = cos a`.
pub fn legendre_integral_to_one(l: usize, x: f64) -> f64 {
    if l == 0 {
        1.0 - x
    } else {
        (legendre(l - 1, x) - legendre(l + 1, x)) / (2.0 * l as f64 + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::gauss_legendre;

    #[test]
    fn monomial_rows_evaluate_to_the_polynomials() {
        let rows = legendre_monomials(6);
        assert_eq!(rows[4], vec![0.375, 0.0, -3.75, 0.0, 4.375, 0.0]);
        for &x in &[-1.0, -0.3, 0.0, 0.42, 1.0] {
            for (l, row) in rows.iter().enumerate() {
                let p: f64 = row.iter().rev().fold(0.0, |acc, c| acc * x + c);
                assert!((p - legendre(l, x)).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn closed_forms_low_degree() {
        for &x in &[-1.0, -0.3, 0.0, 0.42, 1.0] {
            assert!((legendre(2, x) - 0.5 * (3.0 * x * x - 1.0)).abs() < 1e-14);
            assert!((legendre(3, x) - 0.5 * (5.0 * x * x * x - 3.0 * x)).abs() < 1e-14);
            let mut all = [0.0; 6];
            legendre_all(x, &mut all);
            for (l, &p) in all.iter().enumerate() {
                assert!((p - legendre(l, x)).abs() < 1e-14);
            }
        }
        assert!((legendre(40, 1.0) - 1.0).abs() < 1e-12);
        assert!((legendre(41, -1.0) + 1.0).abs() < 1e-12);
    }

    #[test]
    fn orthogonality_by_quadrature() {
        let (nodes, weights) = gauss_legendre(32);
        for l in 0..25 {
            for k in 0..25 {
                let s: f64 = nodes
                    .iter()
                    .zip(&weights)
                    .map(|(&x, &w)| w * legendre(l, x) * legendre(k, x))
                    .sum();
                let expect = if l == k {
                    2.0 / (2.0 * l as f64 + 1.0)
                } else {
                    0.0
                };
                assert!((s - expect).abs() < 1e-12, "l={l} k={k} s={s}");
            }
        }
    }

    #[test]
    fn integral_against_quadrature() {
        let (nodes, weights) = gauss_legendre(40);
        for &x0 in &[-0.9, -0.2, 0.3, 0.95] {
            for l in 0..20 {
                // map [x0, 1] onto [-1, 1]
                let half = 0.5 * (1.0 - x0);
                let s: f64 = nodes
                    .iter()
                    .zip(&weights)
                    .map(|(&t, &w)| w * half * legendre(l, x0 + half * (t + 1.0)))
                    .sum();
                assert!((s - legendre_integral_to_one(l, x0)).abs() < 1e-12);
            }
        }
    }
}
