//! Geometric stiffening against closed forms and an independent Rayleigh–Ritz solution, from
//! the eigenvalues of the bond graph's exact Jacobian (`bondgraph::modes`):
//!
//! * a pinned–pinned column under an axial force P (compression and tension): the first two
//!   bending frequencies are `ω_k √(1 − P/(k² P_cr))`, `P_cr = π²EI/L²` (the sine is the exact
//!   buckling and vibration mode, so the assumed-modes model should give them to rounding);
//! * a cantilever spinning at constant Ω about its root, bending in the plane of rotation
//!   (the only plane of a planar arm): against a Rayleigh–Ritz solution of the linear
//!   rotating-beam equation `ρA ẅ − (N w')' + EI w'''' − ρAΩ² w = 0`,
//!   `N = ½ρAΩ²(L² − x²)`, with a polynomial basis computed here (within 1.3e-4 up to
//!   Ω = 2ω₀; the reference is converged, 9 against 10 functions to 1e-8), and against
//!   Southwell's `ω² = ω₀² + (K − 1)Ω²` in the plane of rotation, with K = 1.1933 the
//!   Rayleigh quotient `∫N̂φ'²/∫ρAφ²` of the non-rotating first mode (the classic
//!   out-of-plane coefficient, ω² = ω₀² + KΩ² for bending out of the plane; in the plane the
//!   centrifugal force also pulls the deflected beam outwards, −Ω²). Southwell's form is the
//!   one-term Rayleigh–Ritz estimate with the non-rotating mode (checked here to 1e-6): exact
//!   in its slope at Ω = 0, an upper bound, and off by its own error as the mode changes with
//!   Ω — 0.55 % at Ω = ω₀, 4.85 % at Ω = 2ω₀ against the converged reference.
//!
//! The spinning beam has clamped–free modes (`Link::with_cantilever_modes`: its joint angle
//! is the root's), and its joint turns at constant Ω because it carries a flywheel of rotary
//! inertia 1e6 times the beam's at x = 0.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use bg_manipulator::{ArmScene, LinearActuator, Link, Pin, PointMass};
use bondgraph::{assign_causality, modes, BondGraph, DMatrix, EffortSource, StateEquations};

/// The bending frequencies (rad/s) of the linearised equations at their initial state,
/// lowest first: the imaginary parts of the complex eigenvalues.
fn frequencies(eqs: &StateEquations) -> Vec<f64> {
    let x0 = eqs.initial_state();
    let mut w: Vec<f64> = modes(eqs, 0.0, &x0)
        .unwrap()
        .iter()
        .filter(|m| m.eigenvalue.im > 1e-6 * m.eigenvalue.norm() && m.eigenvalue.im > 1e-3)
        .map(|m| m.eigenvalue.im)
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

const L: f64 = 8.0;
const EI: f64 = 210e9 * 5.89e-4;
const RHO_A: f64 = 7850.0 * 0.0264;

/// A pinned–pinned column: joint held by a stiff damper, the axial force P (> 0 compression)
/// applied by an actuator from a ground pin on the chord's line to the pin at x = L.
fn column(p: f64, stiffening: bool) -> Vec<f64> {
    let link = Link::rigid(L, RHO_A)
        .unwrap()
        .with_bending_stiffness(EI)
        .unwrap()
        .with_sine_modes(3)
        .unwrap()
        .with_geometric_stiffening(stiffening);
    let mut scene = ArmScene::new(vec![link], 0.0);
    scene.damping = vec![1e12];
    scene.actuators = vec![LinearActuator::new(
        Pin::ground(L + 5.0, 0.0),
        Pin::on_link(0, L),
    )];
    let mut g = BondGraph::new();
    let ports = scene.add_to(&mut g, "col").unwrap();
    let se = g.add("P", EffortSource::new(p)).unwrap();
    let (_, id, port) = ports.iter().find(|q| q.0 == "cyl1").unwrap().clone();
    g.connect((se, None), (id, port)).unwrap();
    let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    frequencies(&eqs)
}

#[test]
fn a_pinned_pinned_column_softens_in_compression_and_stiffens_in_tension() {
    let p_cr = PI * PI * EI / (L * L);
    let omega = |k: f64| (k * PI / L).powi(2) * (EI / RHO_A).sqrt();
    let mut worst: f64 = 0.0;
    for ratio in [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, -0.5, -1.0, -2.0] {
        let w = column(ratio * p_cr, true);
        for k in [1.0, 2.0] {
            let want = omega(k) * (1.0 - ratio / (k * k)).sqrt();
            let got = w[k as usize - 1];
            let err = got / want - 1.0;
            eprintln!("P/P_cr = {ratio:5.2}: ω{k} = {got:10.4} rad/s, closed form {want:10.4} (rel. {err:.1e})");
            worst = worst.max(err.abs());
        }
    }
    assert!(
        worst < 5e-3,
        "worst relative error {worst:e} (asked: 0.5 %)"
    );
    assert!(worst < 1e-6, "the sine is the exact mode: {worst:e}");
    // without the option the axial force does nothing to the bending frequency
    let plain = column(0.5 * p_cr, false);
    assert!((plain[0] / omega(1.0) - 1.0).abs() < 1e-6, "{}", plain[0]);
}

const EI_S: f64 = 1.4e4;
const RHO_A_S: f64 = 1.2;
const L_S: f64 = 10.0;

/// A cantilever spinning at Ω about its clamped root, `modes` sine modes.
fn spinning(omega: f64, modes: u32) -> Vec<f64> {
    let flywheel = 1e6 * RHO_A_S * L_S.powi(3) / 3.0;
    let link = Link::rigid(L_S, RHO_A_S)
        .unwrap()
        .with_bending_stiffness(EI_S)
        .unwrap()
        .with_cantilever_modes(modes)
        .unwrap()
        .with_point_mass(PointMass {
            x: 0.0,
            mass: 0.0,
            inertia: flywheel,
        })
        .unwrap()
        .with_geometric_stiffening(true);
    let mut scene = ArmScene::new(vec![link], 0.0);
    scene.u0 = vec![omega];
    let mut g = BondGraph::new();
    scene.add_to(&mut g, "spin").unwrap();
    let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    frequencies(&eqs)
}

/// The first in-plane frequency of the spinning uniform cantilever by Rayleigh–Ritz with the
/// clamped basis `(x/L)^{i+1}`, i = 1..n, and Gauss–Legendre quadrature (exact for these
/// polynomials).
fn ritz(omega: f64, n: usize) -> (f64, DMatrix<f64>) {
    let rule = bg_manipulator::GaussLegendre::new(40).unwrap();
    let (mut k, mut m): (DMatrix<f64>, DMatrix<f64>) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
    for (x, w) in rule.on(L_S) {
        let s = x / L_S;
        let f = |i: usize| s.powi(i as i32 + 2);
        let d1 = |i: usize| (i + 2) as f64 * s.powi(i as i32 + 1) / L_S;
        let d2 = |i: usize| ((i + 2) * (i + 1)) as f64 * s.powi(i as i32) / (L_S * L_S);
        let axial = 0.5 * RHO_A_S * omega * omega * (L_S * L_S - x * x);
        for a in 0..n {
            for b in 0..n {
                k[(a, b)] += w
                    * (EI_S * d2(a) * d2(b) + axial * d1(a) * d1(b)
                        - RHO_A_S * omega * omega * f(a) * f(b));
                m[(a, b)] += w * RHO_A_S * f(a) * f(b);
            }
        }
    }
    // M = LLᵀ: eigenvalues of L⁻¹ K L⁻ᵀ
    let chol = m.clone().cholesky().unwrap();
    let linv: DMatrix<f64> = chol.l().try_inverse().unwrap();
    let a: DMatrix<f64> = &linv * &k * linv.transpose();
    let eig = a.symmetric_eigen();
    let (i, lambda) = eig
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))
        .unwrap();
    let v = linv.transpose() * eig.eigenvectors.column(i);
    (
        lambda.sqrt(),
        DMatrix::from_column_slice(n, 1, v.as_slice()),
    )
}

#[test]
fn a_spinning_cantilever_stiffens_as_the_rotating_beam_equation_says() {
    let omega0 = 1.875_104_068_711_961_f64.powi(2) * (EI_S / (RHO_A_S * L_S.powi(4))).sqrt();
    let (ritz0, shape) = ritz(0.0, 9);
    assert!((ritz0 / omega0 - 1.0).abs() < 1e-6, "{ritz0} vs {omega0}");
    // Southwell's coefficient from the Rayleigh quotient of the first non-rotating mode:
    // ω² ≈ ω₀² + (K_flap − 1) Ω² in the plane of rotation, K_flap = ∫N̂φ'² / ∫ρAφ²
    let rule = bg_manipulator::GaussLegendre::new(40).unwrap();
    let (mut num, mut den) = (0.0, 0.0);
    for (x, w) in rule.on(L_S) {
        let s = x / L_S;
        let (mut phi, mut d1) = (0.0, 0.0);
        for i in 0..shape.nrows() {
            phi += shape[(i, 0)] * s.powi(i as i32 + 2);
            d1 += shape[(i, 0)] * (i + 2) as f64 * s.powi(i as i32 + 1) / L_S;
        }
        num += w * 0.5 * RHO_A_S * (L_S * L_S - x * x) * d1 * d1;
        den += w * RHO_A_S * phi * phi;
    }
    let k_flap = num / den;
    eprintln!("Southwell coefficient K = {k_flap:.4} (out of plane), K − 1 = {:.4} in plane; ω₀ = {omega0:.4} rad/s", k_flap - 1.0);
    assert!((k_flap - 1.193).abs() < 1e-3, "K = {k_flap}");
    // Southwell's form is Rayleigh's quotient of the rotating beam with the non-rotating mode
    // as the one trial function: R(Ω) = ∫(EIφ''² + Nφ'² − ρAΩ²φ²) / ∫ρAφ² = ω₀² + (K − 1)Ω².
    // A one-term Ritz estimate is an upper bound of the lowest eigenvalue, exact to first
    // order in Ω² (the slope at Ω = 0), and its error grows with Ω as the rotating mode
    // departs from the non-rotating one.
    let rayleigh = |om: f64| {
        let (mut k, mut m) = (0.0, 0.0);
        for (x, w) in rule.on(L_S) {
            let s = x / L_S;
            let (mut phi, mut d1, mut d2) = (0.0, 0.0, 0.0);
            for i in 0..shape.nrows() {
                let c = shape[(i, 0)];
                phi += c * s.powi(i as i32 + 2);
                d1 += c * (i + 2) as f64 * s.powi(i as i32 + 1) / L_S;
                d2 += c * ((i + 2) * (i + 1)) as f64 * s.powi(i as i32) / (L_S * L_S);
            }
            let axial = 0.5 * RHO_A_S * om * om * (L_S * L_S - x * x);
            k += w * (EI_S * d2 * d2 + axial * d1 * d1 - RHO_A_S * om * om * phi * phi);
            m += w * RHO_A_S * phi * phi;
        }
        (k / m).sqrt()
    };
    let (mut worst, mut southwell_to_w0, mut southwell_at_2): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for ratio in [0.0, 0.25, 0.5, 1.0, 1.5, 2.0] {
        let om = ratio * omega0;
        let got = spinning(om, 6)[0];
        let want = ritz(om, 9).0;
        // the reference is converged: 9 against 10 polynomial functions
        let finer = ritz(om, 10).0;
        assert!(
            (want / finer - 1.0).abs() < 1e-8,
            "Ritz not converged at {ratio}"
        );
        let southwell = (omega0 * omega0 + (k_flap - 1.0) * om * om).sqrt();
        assert!(
            (rayleigh(om) / southwell - 1.0).abs() < 1e-6,
            "Southwell's form is the one-mode Rayleigh quotient"
        );
        let err = got / want - 1.0;
        let one_mode = southwell / want - 1.0;
        eprintln!(
            "Ω/ω₀ = {ratio:4.2}: ω₁ = {got:8.5} rad/s, converged Ritz {want:8.5} (model rel. {err:+.1e}); \
             Southwell (one mode) {southwell:8.5} (rel. to Ritz {one_mode:+.2e}); out of plane ω₀² + KΩ² would be {:8.5}",
            (omega0 * omega0 + k_flap * om * om).sqrt()
        );
        worst = worst.max(err.abs());
        // an upper bound, as a one-term Ritz estimate must be
        assert!(
            one_mode > -1e-9,
            "Southwell below the converged value at {ratio}"
        );
        if ratio <= 1.0 {
            southwell_to_w0 = southwell_to_w0.max(one_mode);
        } else {
            southwell_at_2 = one_mode;
        }
    }
    // our model against the converged reference: measured 1.3e-4 at Ω = 2ω₀ (six modes)
    assert!(worst < 2e-4, "model vs converged Ritz: {worst:e}");
    // the one-mode formula's own error: measured 0.55 % at Ω = ω₀, 4.85 % at Ω = 2ω₀
    assert!(southwell_to_w0 < 6e-3, "{southwell_to_w0:e}");
    assert!(
        (0.047..0.050).contains(&southwell_at_2),
        "{southwell_at_2:e}"
    );
}
