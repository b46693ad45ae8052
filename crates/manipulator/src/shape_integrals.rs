//! Shape integrals of a link (its inertia invariants), computed once when the arm is built.
//!
//! In frame i the cross-section at distance x sits at `r(x) = (x, w(x))` with
//! `w = Σ_k ψ_k(x) q_k` (nothing linearised) and turns by `θ(x) = Σ_k θ_k(x) q_k`. Every
//! quantity the dynamics sum along a link — M (eq. 42), T (eq. 41), E = ∂T/∂q (eq. 44), Ṁu,
//! G and V_g (eqs. 45–48), the reactions (eq. 97) — is a quadratic form in the station
//! features
//!
//! ```text
//! φ(x) = [1, x, ψ_1(x) … ψ_m(x)]     position and velocity, weight ρA (eq. 40)
//! χ(x) = [1, θ_1(x) … θ_m(x)]        rotation, weight ρI (eq. 40)
//! ```
//!
//! with coefficients that depend on q and u only. So each link carries the Gram matrices
//!
//! ```text
//! G_A = ∫ ρA φφᵀ dx + Σ_point masses m φ(x₀)φ(x₀)ᵀ
//! G_I = ∫ ρI χχᵀ dx + Σ_point masses J χ(x₀)χ(x₀)ᵀ
//! K   = EI ∫ ψ''ψ''ᵀ dx                                        (eq. 51)
//! ```
//!
//! and a sum over the stations of a link becomes a contraction with them: O(m²) per link and
//! call instead of O(points × m) (the inertia invariants of floating-frame codes).
//!
//! Sine modes `ψ = sin(κx)` ([`ModeShape::sine_wavenumber`]) are integrated in closed form,
//! with `S(d) = ∫₀ᴸ cos(dx) dx = sin(dL)/d`:
//!
//! ```text
//! ∫ sin κx = 2 sin²(κL/2)/κ        ∫ x sin κx = (sin κL − κL cos κL)/κ²     ∫ κ cos κx = sin κL
//! ∫ sin_a sin_b = ½(S(a−b) − S(a+b))                 ∫ cos_a cos_b = ½(S(a−b) + S(a+b))
//! ```
//!
//! A link with any other [`ModeShape`] is integrated by Gauss–Legendre quadrature with at
//! least [`ShapeIntegrals::MIN_QUADRATURE_POINTS`] points, once.

use nalgebra::DMatrix;

use crate::geometric_stiffening::ShorteningIntegrals;
use crate::link::Link;
use crate::mode_shape::ModeShape;
use crate::quadrature::GaussLegendre;
use bondgraph::ParamError;

/// The Gram matrices of one link's station features.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeIntegrals {
    /// G_A, (2 + m) × (2 + m).
    translation: DMatrix<f64>,
    /// G_I, (1 + m) × (1 + m).
    rotation: DMatrix<f64>,
    /// K of the link's modes, m × m.
    bending: DMatrix<f64>,
    /// With geometric stiffening: the integrals of the shortening.
    shortening: Option<ShorteningIntegrals>,
    /// Entries of G_A and G_I read per evaluation, laid out for it (see [`Self::finish`]).
    fast: FastEntries,
}

/// The invariants the right-hand side reads on every evaluation, copied out of G_A and G_I
/// once so that the loops run over contiguous memory (the same numbers, bit for bit).
#[derive(Clone, Debug, Default, PartialEq)]
struct FastEntries {
    /// `[a_k, b_k, ∫ρI θ_k]` per mode k.
    joint_mode: Vec<[f64; 3]>,
    /// The modes' block of M, `0 + (P_kl + ∫ρI θ_k θ_l)`, column-major m × m.
    modal_mass: Vec<f64>,
    /// `P_kl = ∫ρA ψ_k ψ_l`, row-major m × m (row k contiguous).
    mode_products: Vec<f64>,
}

/// The ρA-weighted moments of a link's deflection at (q, u) that the dynamics need:
/// contractions of G_A with the link's modal coordinates q^b and speeds u^b.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct DeflectionMoments {
    /// `∫ρA w = aᵀq` with `a = ∫ρA ψ`.
    pub(crate) w: f64,
    /// `∫ρA ẇ = aᵀu`.
    pub(crate) w_dot: f64,
    /// `∫ρA x ẇ = bᵀu` with `b = ∫ρA x ψ`.
    pub(crate) x_w_dot: f64,
    /// `∫ρA w² = qᵀPq` with `P = ∫ρA ψψᵀ`.
    pub(crate) w_w: f64,
    /// `∫ρA w ẇ = qᵀPu`.
    pub(crate) w_w_dot: f64,
    /// `∫ρA ẇ² = uᵀPu`.
    pub(crate) w_dot_w_dot: f64,
}

/// `∫₀ᴸ cos(dx) dx`.
fn cos_integral(d: f64, l: f64) -> f64 {
    let t = d * l;
    if t.abs() < 1e-6 {
        l * (1.0 - t * t / 6.0)
    } else {
        t.sin() / d
    }
}

impl ShapeIntegrals {
    /// Quadrature points used at least for links whose modes are not all sines.
    pub const MIN_QUADRATURE_POINTS: usize = 64;

    /// The integrals of `link`; modes other than sines are integrated with
    /// `max(points, MIN_QUADRATURE_POINTS)` Gauss–Legendre points.
    pub fn of(link: &Link, points: usize) -> Result<Self, ParamError> {
        let m = link.modes().len();
        let mut s = Self {
            translation: DMatrix::zeros(m + 2, m + 2),
            rotation: DMatrix::zeros(m + 1, m + 1),
            bending: DMatrix::zeros(m, m),
            shortening: None,
            fast: FastEntries::default(),
        };
        let sines: Option<Vec<f64>> = if link.is_uniform() {
            link.modes().iter().map(|p| p.sine_wavenumber()).collect()
        } else {
            None
        };
        match sines {
            Some(kappa) => s.add_sines(link, &kappa),
            None => s.add_quadrature(
                link,
                &GaussLegendre::new(points.max(Self::MIN_QUADRATURE_POINTS))?,
            ),
        }
        let (mut phi, mut chi) = (vec![0.0; m + 2], vec![0.0; m + 1]);
        for pm in link.point_masses() {
            features(link.modes(), pm.x, &mut phi, &mut chi);
            add_outer(&mut s.translation, pm.mass, &phi);
            add_outer(&mut s.rotation, pm.inertia, &chi);
        }
        if link.geometric_stiffening() {
            s.shortening = Some(ShorteningIntegrals::of(link, points)?);
        }
        s.finish();
        Ok(s)
    }

    /// Copy the entries of [`FastEntries`] out of the finished G_A and G_I.
    fn finish(&mut self) {
        let m = self.n_modes();
        self.fast = FastEntries {
            joint_mode: (0..m)
                .map(|k| [self.mode_mass(k), self.mode_moment(k), self.rotary_mode(k)])
                .collect(),
            modal_mass: (0..m * m)
                .map(|lk| {
                    let (l, k) = (lk / m, lk % m);
                    0.0 + (self.mode_product(k, l) + self.rotary_product(k, l))
                })
                .collect(),
            mode_products: (0..m * m)
                .map(|kl| self.mode_product(kl / m, kl % m))
                .collect(),
        };
    }

    /// `[a_k, b_k, ∫ρI θ_k]` per mode k: the constants of the joint–mode entries of M.
    pub(crate) fn joint_mode_constants(&self) -> &[[f64; 3]] {
        &self.fast.joint_mode
    }
    /// The modes' own block of M, `0 + (P_kl + ∫ρI θ_k θ_l)`, column-major m × m.
    pub(crate) fn modal_mass(&self) -> &[f64] {
        &self.fast.modal_mass
    }

    fn add_sines(&mut self, link: &Link, kappa: &[f64]) {
        let (l, rho_a, rho_i, ei) = (
            link.length(),
            link.mass_per_length(),
            link.rotary_inertia_per_length(),
            link.bending_stiffness(),
        );
        let (ga, gi) = (&mut self.translation, &mut self.rotation);
        ga[(0, 0)] = rho_a * l;
        ga[(0, 1)] = rho_a * l * l / 2.0;
        ga[(1, 1)] = rho_a * l * l * l / 3.0;
        gi[(0, 0)] = rho_i * l;
        for (a, &ka) in kappa.iter().enumerate() {
            let (s, c) = (ka * l).sin_cos();
            let half = (ka * l / 2.0).sin();
            ga[(0, 2 + a)] = rho_a * 2.0 * half * half / ka;
            ga[(1, 2 + a)] = rho_a * (s - ka * l * c) / (ka * ka);
            gi[(0, 1 + a)] = rho_i * s;
            for (b, &kb) in kappa.iter().enumerate().skip(a) {
                let (minus, plus) = (cos_integral(ka - kb, l), cos_integral(ka + kb, l));
                let (sin_sin, cos_cos) = (0.5 * (minus - plus), 0.5 * (minus + plus));
                ga[(2 + a, 2 + b)] = rho_a * sin_sin;
                gi[(1 + a, 1 + b)] = rho_i * ka * kb * cos_cos;
                self.bending[(a, b)] = ei * ka * ka * kb * kb * sin_sin;
                self.bending[(b, a)] = self.bending[(a, b)];
            }
        }
        ga.fill_lower_triangle_with_upper_triangle();
        gi.fill_lower_triangle_with_upper_triangle();
    }

    fn add_quadrature(&mut self, link: &Link, rule: &GaussLegendre) {
        let m = link.modes().len();
        let (mut phi, mut chi, mut curv) = (vec![0.0; m + 2], vec![0.0; m + 1], vec![0.0; m]);
        for (x, w) in rule.on(link.length()) {
            features(link.modes(), x, &mut phi, &mut chi);
            for (c, mode) in curv.iter_mut().zip(link.modes()) {
                *c = mode.curvature(x);
            }
            add_outer(&mut self.translation, w * link.mass_per_length_at(x), &phi);
            add_outer(
                &mut self.rotation,
                w * link.rotary_inertia_per_length_at(x),
                &chi,
            );
            add_outer(&mut self.bending, w * link.bending_stiffness_at(x), &curv);
        }
    }

    /// `G_A = ∫ρA φφᵀ dx + Σ m φφᵀ`, φ = [1, x, ψ_1 … ψ_m].
    #[must_use]
    pub fn translation(&self) -> &DMatrix<f64> {
        &self.translation
    }
    /// `G_I = ∫ρI χχᵀ dx + Σ J χχᵀ`, χ = [1, θ_1 … θ_m].
    #[must_use]
    pub fn rotation(&self) -> &DMatrix<f64> {
        &self.rotation
    }
    /// `EI ∫ψ''ψ''ᵀ dx`: the link's block of K (eq. 51).
    #[must_use]
    pub fn bending(&self) -> &DMatrix<f64> {
        &self.bending
    }
    /// The integrals of the axial shortening, if the link keeps it
    /// ([`geometric_stiffening`](crate::geometric_stiffening)).
    #[must_use]
    pub fn shortening(&self) -> Option<&ShorteningIntegrals> {
        self.shortening.as_ref()
    }
    /// Number of modes m.
    #[must_use]
    pub fn n_modes(&self) -> usize {
        self.bending.nrows()
    }

    /// Mass `∫ρA dx + Σ m` (kg).
    pub(crate) fn mass(&self) -> f64 {
        self.translation[(0, 0)]
    }
    /// First moment `∫ρA x dx + Σ m x₀` (kg·m).
    pub(crate) fn first_moment(&self) -> f64 {
        self.translation[(0, 1)]
    }
    /// Second moment `∫ρA x² dx + Σ m x₀²` (kg·m²).
    pub(crate) fn second_moment(&self) -> f64 {
        self.translation[(1, 1)]
    }
    /// `a_k = ∫ρA ψ_k`.
    pub(crate) fn mode_mass(&self, k: usize) -> f64 {
        self.translation[(0, 2 + k)]
    }
    /// `b_k = ∫ρA x ψ_k`.
    pub(crate) fn mode_moment(&self, k: usize) -> f64 {
        self.translation[(1, 2 + k)]
    }
    /// `P_kl = ∫ρA ψ_k ψ_l`.
    pub(crate) fn mode_product(&self, k: usize, l: usize) -> f64 {
        self.translation[(2 + k, 2 + l)]
    }
    /// `∫ρI` (kg·m).
    pub(crate) fn rotary(&self) -> f64 {
        self.rotation[(0, 0)]
    }
    /// `∫ρI θ_k`.
    pub(crate) fn rotary_mode(&self, k: usize) -> f64 {
        self.rotation[(0, 1 + k)]
    }
    /// `∫ρI θ_k θ_l`.
    pub(crate) fn rotary_product(&self, k: usize, l: usize) -> f64 {
        self.rotation[(1 + k, 1 + l)]
    }

    /// The moments of the deflection with modal coordinates `q` and speeds `u` (m each).
    pub(crate) fn deflection_moments(&self, q: &[f64], u: &[f64]) -> DeflectionMoments {
        let m = self.n_modes();
        let (q, u) = (&q[..m], &u[..m]);
        let mut d = DeflectionMoments::default();
        let rows = self.fast.mode_products.chunks_exact(m.max(1));
        for ((row, [a, b, _]), (qk, uk)) in rows.zip(&self.fast.joint_mode).zip(q.iter().zip(u)) {
            // (Pq)_k, (Pu)_k
            let (mut pq, mut pu) = (0.0, 0.0);
            for (p, (ql, ul)) in row.iter().zip(q.iter().zip(u)) {
                pq += p * ql;
                pu += p * ul;
            }
            d.w += a * qk;
            d.w_dot += a * uk;
            d.x_w_dot += b * uk;
            d.w_w += qk * pq;
            d.w_w_dot += qk * pu;
            d.w_dot_w_dot += uk * pu;
        }
        d
    }

    /// `(∫ρA w, ∫ρA w²) = (aᵀq, qᵀPq)`: the moments the mass matrix reads, the same numbers
    /// as those of [`deflection_moments`](Self::deflection_moments)`(q, q)`.
    pub(crate) fn deflection_and_square(&self, q: &[f64]) -> (f64, f64) {
        let m = self.n_modes();
        let q = &q[..m];
        let (mut w, mut w_w) = (0.0, 0.0);
        let rows = self.fast.mode_products.chunks_exact(m.max(1));
        for ((row, [a, ..]), qk) in rows.zip(&self.fast.joint_mode).zip(q) {
            let mut pq = 0.0;
            for (p, ql) in row.iter().zip(q) {
                pq += p * ql;
            }
            w += a * qk;
            w_w += qk * pq;
        }
        (w, w_w)
    }

    /// `(Pq)_k = ∫ρA ψ_k w`.
    pub(crate) fn mode_times_deflection(&self, k: usize, q: &[f64]) -> f64 {
        let m = self.n_modes();
        let row = &self.fast.mode_products[k * m..(k + 1) * m];
        row.iter().zip(q).map(|(p, ql)| p * ql).sum()
    }
}

/// φ(x) and χ(x) of the modes at x.
fn features(modes: &[std::sync::Arc<dyn ModeShape>], x: f64, phi: &mut [f64], chi: &mut [f64]) {
    phi[0] = 1.0;
    phi[1] = x;
    chi[0] = 1.0;
    for (k, mode) in modes.iter().enumerate() {
        phi[2 + k] = mode.value(x);
        chi[1 + k] = mode.slope(x);
    }
}

/// `g += w vvᵀ` (exactly symmetric).
fn add_outer(g: &mut DMatrix<f64>, w: f64, v: &[f64]) {
    for (a, va) in v.iter().enumerate() {
        for (b, vb) in v.iter().enumerate().skip(a) {
            let x = w * va * vb;
            g[(a, b)] += x;
            if b != a {
                g[(b, a)] += x;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::SineMode;

    /// A sine mode that does not say so: integrated by quadrature.
    #[derive(Debug)]
    struct Anonymous(SineMode);
    impl ModeShape for Anonymous {
        fn value(&self, x: f64) -> f64 {
            self.0.value(x)
        }
        fn slope(&self, x: f64) -> f64 {
            self.0.slope(x)
        }
        fn curvature(&self, x: f64) -> f64 {
            self.0.curvature(x)
        }
    }

    #[test]
    fn closed_form_matches_quadrature_for_sines() {
        let beam = Link::beam(8.0, 210e9, 7850.0, 0.0264, 5.89e-4).unwrap();
        let with_point = |l: Link| {
            l.with_point_mass(crate::PointMass {
                x: 3.0,
                mass: 200.0,
                inertia: 7.0,
            })
            .unwrap()
        };
        let closed = with_point(beam.clone().with_sine_modes(10).unwrap());
        let quad = with_point((1..=10).fold(beam, |l, k| {
            l.with_mode(Arc::new(Anonymous(SineMode::new(k, 8.0))))
                .unwrap()
        }));
        let (a, b) = (
            ShapeIntegrals::of(&closed, 16).unwrap(),
            ShapeIntegrals::of(&quad, 16).unwrap(),
        );
        for (x, y) in [
            (a.translation(), b.translation()),
            (a.rotation(), b.rotation()),
            (a.bending(), b.bending()),
        ] {
            let err = (x - y).abs().max() / y.abs().max();
            assert!(err < 1e-14, "{err:e}");
            assert!((x - x.transpose()).abs().max() == 0.0);
        }
        // hinged–hinged sines are orthogonal: ∫ρA ψ_k ψ_l = ρA L/2 δ_kl, plus the point mass
        let rho_a = 7850.0 * 0.0264;
        let psi3 = (3.0 * std::f64::consts::PI * 3.0 / 8.0).sin();
        let want = rho_a * 4.0 + 200.0 * psi3 * psi3;
        assert!((a.mode_product(2, 2) - want).abs() < 1e-12 * want);
        assert_eq!(a.n_modes(), 10);
    }

    #[test]
    fn a_rigid_rod_and_a_pendulum() {
        let rod = ShapeIntegrals::of(&Link::rigid(2.0, 3.0).unwrap(), 1).unwrap();
        for (got, want) in [
            (rod.mass(), 6.0),
            (rod.first_moment(), 6.0),
            (rod.second_moment(), 8.0),
        ] {
            assert!((got - want).abs() < 1e-15 * want);
        }
        let p = ShapeIntegrals::of(&Link::pendulum(6.0, 5000.0).unwrap(), 16).unwrap();
        let want = nalgebra::dmatrix![5000.0, 30000.0; 30000.0, 180000.0];
        assert!((p.translation() - want).abs().max() < 1e-9);
        assert!(p.rotary().abs() < 1e-300);
    }

    /// The deflection moments as written before the row-major copy of P (the reference).
    fn moments_reference(g: &ShapeIntegrals, q: &[f64], u: &[f64]) -> DeflectionMoments {
        let mut d = DeflectionMoments::default();
        for k in 0..q.len() {
            let (mut pq, mut pu) = (0.0, 0.0);
            for l in 0..q.len() {
                let p = g.mode_product(k, l);
                pq += p * q[l];
                pu += p * u[l];
            }
            let (a, b) = (g.mode_mass(k), g.mode_moment(k));
            d.w += a * q[k];
            d.w_dot += a * u[k];
            d.x_w_dot += b * u[k];
            d.w_w += q[k] * pq;
            d.w_w_dot += q[k] * pu;
            d.w_dot_w_dot += u[k] * pu;
        }
        d
    }

    #[test]
    fn contiguous_moments_give_the_bits_of_the_matrix_entries() {
        let beam = Link::beam(8.0, 210e9, 7850.0, 0.0264, 5.89e-4).unwrap();
        let point = crate::PointMass {
            x: 3.0,
            mass: 200.0,
            inertia: 7.0,
        };
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            match state % 11 {
                0 => 0.0,
                1 => -0.0,
                r => (state >> 11) as f64 / (1u64 << 53) as f64 * 1e-2 - 5e-3 + r as f64 * 1e-4,
            }
        };
        for modes in 0..=6 {
            let sines = beam.clone().with_sine_modes(modes).unwrap();
            let quad = (1..=modes).fold(beam.clone(), |l, k| {
                l.with_mode(Arc::new(Anonymous(SineMode::new(k, 8.0))))
                    .unwrap()
            });
            for link in [sines.clone(), quad, sines.with_point_mass(point).unwrap()] {
                let g = ShapeIntegrals::of(&link, 16).unwrap();
                for _ in 0..200 {
                    let q: Vec<f64> = (0..modes).map(|_| next()).collect();
                    let u: Vec<f64> = (0..modes).map(|_| next()).collect();
                    let (got, want) = (g.deflection_moments(&q, &u), moments_reference(&g, &q, &u));
                    let bits = |d: DeflectionMoments| {
                        [d.w, d.w_dot, d.x_w_dot, d.w_w, d.w_w_dot, d.w_dot_w_dot].map(f64::to_bits)
                    };
                    assert_eq!(bits(got), bits(want));
                    let square = moments_reference(&g, &q, &q);
                    let (w, w_w) = g.deflection_and_square(&q);
                    assert_eq!(
                        [w, w_w].map(f64::to_bits),
                        [square.w, square.w_w].map(f64::to_bits)
                    );
                    for k in 0..q.len() {
                        let old: f64 = (0..q.len()).map(|l| g.mode_product(k, l) * q[l]).sum();
                        assert_eq!(g.mode_times_deflection(k, &q).to_bits(), old.to_bits());
                    }
                }
            }
        }
    }
}
