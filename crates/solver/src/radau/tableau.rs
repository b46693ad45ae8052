//! The Radau IIA (s = 3) coefficients and everything derived from them: the eigen-decomposition
//! of A⁻¹ that splits the Newton system into one real and one complex block, the embedded
//! error formula and the constants of the collocation polynomial.
//!
//! Only `A` and `c` are typed in (Hairer & Wanner II, Table IV.5.6); the rest is computed from
//! them once per integrator, and the unit tests check every derived quantity against its
//! defining property.

/// Radau IIA constants, all derived from `A` and `c`.
#[derive(Clone, Debug)]
pub(crate) struct Tableau {
    /// Nodes c₁ = (4−√6)/10, c₂ = (4+√6)/10, c₃ = 1.
    pub c: [f64; 3],
    /// Real eigenvalue γ of A⁻¹ (γ = 1/γ₀, γ₀ the real eigenvalue of A).
    pub gamma: f64,
    /// Complex eigenvalues α ± iβ of A⁻¹.
    pub alpha: f64,
    /// See `alpha`.
    pub beta: f64,
    /// T with T⁻¹A⁻¹T = diag(γ, [[α, −β], [β, α]]), row-major; last row (1, 1, 0).
    pub t: [[f64; 3]; 3],
    /// T⁻¹, row-major.
    pub ti: [[f64; 3]; 3],
    /// Error estimate: err = (γ/h − J)⁻¹ (f(t₀, y₀) + Σₖ dₖ zₖ / h).
    pub d: [f64; 3],
}

/// The Radau IIA coefficient matrix A (row-major).
pub(crate) fn radau_a() -> [[f64; 3]; 3] {
    let s6 = 6f64.sqrt();
    [
        [
            (88.0 - 7.0 * s6) / 360.0,
            (296.0 - 169.0 * s6) / 1800.0,
            (-2.0 + 3.0 * s6) / 225.0,
        ],
        [
            (296.0 + 169.0 * s6) / 1800.0,
            (88.0 + 7.0 * s6) / 360.0,
            (-2.0 - 3.0 * s6) / 225.0,
        ],
        [(16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0],
    ]
}

type M3 = [[f64; 3]; 3];

fn det3(m: &M3) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Inverse by the adjugate (the matrices here are well conditioned 3×3).
pub(crate) fn inv3(m: &M3) -> M3 {
    let d = det3(m);
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            // Cofactor of m[j][i].
            let (r0, r1) = ((j + 1) % 3, (j + 2) % 3);
            let (c0, c1) = ((i + 1) % 3, (i + 2) % 3);
            *v = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / d;
        }
    }
    r
}

/// Complex number as (re, im), enough for one 3×3 eigenvector.
type C = (f64, f64);
fn cmul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}
fn csub(a: C, b: C) -> C {
    (a.0 - b.0, a.1 - b.1)
}
fn cdiv(a: C, b: C) -> C {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

/// A null vector of the rank-2 complex 3×3 matrix `m`: the (bilinear) cross product of its
/// first two rows, scaled so that its last component is 1.
fn null_vector(m: &[[C; 3]; 3]) -> [C; 3] {
    let (a, b) = (m[0], m[1]);
    let v = [
        csub(cmul(a[1], b[2]), cmul(a[2], b[1])),
        csub(cmul(a[2], b[0]), cmul(a[0], b[2])),
        csub(cmul(a[0], b[1]), cmul(a[1], b[0])),
    ];
    [cdiv(v[0], v[2]), cdiv(v[1], v[2]), (1.0, 0.0)]
}

impl Tableau {
    /// Derive every constant from `A` and `c`.
    pub(crate) fn new() -> Self {
        let s6 = 6f64.sqrt();
        let c = [(4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0];
        let a = radau_a();
        let ai = inv3(&a);
        // Characteristic polynomial of A⁻¹: λ³ − p₁λ² + p₂λ − p₃.
        let p1 = ai[0][0] + ai[1][1] + ai[2][2];
        let p2 = (ai[0][0] * ai[1][1] - ai[0][1] * ai[1][0])
            + (ai[0][0] * ai[2][2] - ai[0][2] * ai[2][0])
            + (ai[1][1] * ai[2][2] - ai[1][2] * ai[2][1]);
        let p3 = det3(&ai);
        // The one real root, by Newton from above (the cubic is increasing and convex there).
        let mut gamma = p1;
        for _ in 0..100 {
            let f = ((gamma - p1) * gamma + p2) * gamma - p3;
            let df = (3.0 * gamma - 2.0 * p1) * gamma + p2;
            let step = f / df;
            gamma -= step;
            if step.abs() <= 1e-15 * gamma.abs() {
                break;
            }
        }
        // Deflate: λ² − (p₁ − γ)λ + p₃/γ has the roots α ± iβ.
        let alpha = (p1 - gamma) / 2.0;
        let beta = (p3 / gamma - alpha * alpha).sqrt();
        // Eigenvectors: v₁ for γ, v = vr + i·vi for α + iβ; T = [v₁, vr, −vi] gives
        // A⁻¹T = T·diag(γ, [[α, −β], [β, α]]).
        let shifted = |lre: f64, lim: f64| {
            let mut m = [[(0.0, 0.0); 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] = (ai[i][j], 0.0);
                }
                m[i][i] = (ai[i][i] - lre, -lim);
            }
            m
        };
        let v1 = null_vector(&shifted(gamma, 0.0));
        let v = null_vector(&shifted(alpha, beta));
        let mut t = [[0.0; 3]; 3];
        for i in 0..3 {
            t[i] = [v1[i].0, v[i].0, -v[i].1];
        }
        let ti = inv3(&t);
        // Embedded formula of order 3: ŷ = y₀ + h(γ₀ f(t₀, y₀) + Σ b̂ᵢ f(Yᵢ)) with γ₀ = 1/γ and
        // b̂ from the quadrature conditions Σ b̂ᵢ cᵢ^(k−1) = 1/k − γ₀·[k = 1], k = 1, 2, 3.
        let g0 = 1.0 / gamma;
        let vand = [
            [1.0, 1.0, 1.0],
            [c[0], c[1], c[2]],
            [c[0] * c[0], c[1] * c[1], c[2] * c[2]],
        ];
        let rhs = [1.0 - g0, 0.5, 1.0 / 3.0];
        let vi = inv3(&vand);
        let mut bhat = [0.0; 3];
        for (i, b) in bhat.iter_mut().enumerate() {
            *b = (0..3).map(|k| vi[i][k] * rhs[k]).sum();
        }
        // ŷ − y = γ₀h f₀ + Σⱼ eⱼ zⱼ with e = (b̂ − b)ᵀA⁻¹ (since h f(Yᵢ) = (A⁻¹Z)ᵢ), and
        // (I − γ₀hJ)⁻¹(ŷ − y) = (γ/h − J)⁻¹(f₀ + Σⱼ γ eⱼ zⱼ / h): d = γ·e.
        let b = a[2];
        let mut d = [0.0; 3];
        for (j, dj) in d.iter_mut().enumerate() {
            *dj = gamma * (0..3).map(|i| (bhat[i] - b[i]) * ai[i][j]).sum::<f64>();
        }
        Self {
            c,
            gamma,
            alpha,
            beta,
            t,
            ti,
            d,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mul(a: &M3, b: &M3) -> M3 {
        let mut r = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                r[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        r
    }

    /// A is the collocation matrix: Σⱼ aᵢⱼ cⱼ^(k−1) = cᵢ^k / k for k = 1, 2, 3.
    #[test]
    fn a_satisfies_the_collocation_conditions() {
        let tab = Tableau::new();
        let a = radau_a();
        for (i, row) in a.iter().enumerate() {
            for k in 1..=3 {
                let lhs: f64 = (0..3).map(|j| row[j] * tab.c[j].powi(k - 1)).sum();
                let want = tab.c[i].powi(k) / f64::from(k);
                assert!(
                    (lhs - want).abs() < 1e-15,
                    "row {i}, k {k}: {lhs} vs {want}"
                );
            }
        }
    }

    /// The eigenvalues of A⁻¹ are the published ones (Hairer & Wanner II, IV.8) and T
    /// block-diagonalises A⁻¹.
    #[test]
    fn t_block_diagonalises_a_inverse() {
        let tab = Tableau::new();
        assert!((tab.gamma - 3.637_834_252_744_496).abs() < 1e-13);
        assert!((tab.alpha - 2.681_082_873_627_752).abs() < 1e-13);
        assert!((tab.beta - 3.050_430_199_247_41).abs() < 1e-13);
        let lam = mul(&mul(&tab.ti, &inv3(&radau_a())), &tab.t);
        let want = [
            [tab.gamma, 0.0, 0.0],
            [0.0, tab.alpha, -tab.beta],
            [0.0, tab.beta, tab.alpha],
        ];
        for i in 0..3 {
            for j in 0..3 {
                assert!((lam[i][j] - want[i][j]).abs() < 1e-12, "{lam:?}");
            }
        }
        assert!((tab.t[2][0] - 1.0).abs() < 1e-15 && (tab.t[2][1] - 1.0).abs() < 1e-15);
        assert!(tab.t[2][2].abs() < 1e-15);
    }

    /// The embedded formula's coefficients are RADAU5's d = (−(13+7√6)/3, (−13+7√6)/3, −1/3).
    #[test]
    fn error_coefficients_match_radau5() {
        let tab = Tableau::new();
        let s6 = 6f64.sqrt();
        let want = [
            -(13.0 + 7.0 * s6) / 3.0,
            (-13.0 + 7.0 * s6) / 3.0,
            -1.0 / 3.0,
        ];
        for k in 0..3 {
            assert!(
                (tab.d[k] - want[k]).abs() < 1e-12,
                "{:?} vs {want:?}",
                tab.d
            );
        }
    }
}
