//! The Gram-matrix dynamics ([`ArmKinematics`]) against the per-station reference
//! ([`StationKinematics`]: the quadrature sums over stations with their projection matrices,
//! as the code computed before the shape integrals) at random configurations, speeds and
//! accelerations: M, E, Ṁu, G, V_g, T and the reactions (with loads and rigid extra masses).
//!
//! Each difference is taken relative to the largest entry of the reference quantity (for
//! T and V_g: to the largest of |T|, Σ m g |y| over the random draws of that arm). The
//! reference integrates with enough Gauss–Legendre points that its own quadrature error is
//! below rounding, so what remains is the rounding of two different summation orders.
//! Measured: M, G, V_g, T and ρ within 1e-15, E within 7e-15, Ṁu within 2.3e-14 (its terms
//! cancel: the reference sums them per station, the contraction per link); the tests ask for
//! 1e-13.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use bg_manipulator::reference::StationKinematics;
use bg_manipulator::{ArmKinematics, Link, PlanarArm, PointLoad, PointMass};
use common::{crane_links, Rng, G};
use nalgebra::{DMatrix, DVector, Vector2};

const TOL: f64 = 1e-13;

fn rel_m(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).abs().max() / b.abs().max()
}
fn rel_v(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    let s = b.abs().max();
    if s <= 0.0 {
        a.abs().max()
    } else {
        (a - b).abs().max() / s
    }
}

/// The worst relative differences (M, E, Ṁu, G, V_g, T, ρ) over `draws` random states.
fn compare(arm: &PlanarArm, seed: u64, draws: usize) -> [f64; 7] {
    let mut rng = Rng::new(seed);
    let mut worst = [0.0f64; 7];
    for _ in 0..draws {
        let q = rng.q(arm, 0.3);
        let u = rng.vec(arm.n(), 1.0);
        let u_dot = rng.vec(arm.n(), 3.0);
        let (new, old) = (arm.kinematics(&q), StationKinematics::new(arm, &q));
        let (e, mdot_u) = new.kinetic_terms(&u);
        let (e_ref, mdot_u_ref) = old.kinetic_terms(&u);
        let (g, v) = new.gravity_terms(true);
        let (g_ref, v_ref) = old.gravity_terms(true);
        let (t, t_ref) = (new.kinetic_energy(&u), old.kinetic_energy(&u));
        // loads and rigid extra masses at random stations
        let mut loads = Vec::new();
        let mut masses = Vec::new();
        for (i, l) in arm.links().iter().enumerate() {
            let s = arm.station(i, rng.uniform(0.0, l.length())).unwrap();
            loads.push(PointLoad {
                station: s.clone(),
                force: Vector2::new(rng.uniform(-1e5, 1e5), rng.uniform(-1e5, 1e5)),
            });
            masses.push((s, rng.uniform(10.0, 1000.0)));
        }
        let rho = new.reactions(&u, &u_dot, &loads, &masses);
        let rho_ref = old.reactions(&u, &u_dot, &loads, &masses);
        let scale_v = energy_scale(&new, v_ref);
        for (w, d) in worst.iter_mut().zip([
            rel_m(&new.mass_matrix(), &old.mass_matrix()),
            rel_v(&e, &e_ref),
            rel_v(&mdot_u, &mdot_u_ref),
            rel_v(&g, &g_ref),
            (v - v_ref).abs() / scale_v,
            (t - t_ref).abs() / t_ref.abs(),
            rel_v(&rho, &rho_ref),
        ]) {
            *w = w.max(d);
        }
        // the public acceleration of a point agrees too
        let s = &loads[0].station;
        let a = new.point_acceleration(s, &u, &u_dot);
        let a_ref = old.point_acceleration(s, &u, &u_dot);
        assert!(
            (a - a_ref).norm() <= TOL * a_ref.norm().max(1.0),
            "{a} vs {a_ref}"
        );
    }
    worst
}

/// `Σ_links m g (|y_joint| + L)`: the scale of V_g.
fn energy_scale(kin: &ArmKinematics<'_>, v: f64) -> f64 {
    let arm = kin.arm();
    let s: f64 = arm
        .links()
        .iter()
        .enumerate()
        .map(|(i, l)| l.mass() * arm.gravity() * (kin.pose().origin(i).y.abs() + l.length()))
        .sum();
    s.max(v.abs())
}

fn check(name: &str, arm: &PlanarArm, seed: u64) {
    let worst = compare(arm, seed, 20);
    let shown: Vec<String> = worst.iter().map(|w| format!("{w:.1e}")).collect();
    eprintln!("{name}: M, E, Ṁu, G, V_g, T, ρ: {}", shown.join(", "));
    for (what, w) in ["M", "E", "Ṁu", "G", "V_g", "T", "ρ"].iter().zip(worst) {
        assert!(w <= TOL, "{name}: {what} differs by {w:e}");
    }
}

#[test]
fn the_knuckle_boom_with_1_2_3_and_10_modes() {
    for modes in [1, 2, 3] {
        let arm = PlanarArm::with_quadrature(crane_links(modes), G, 24).unwrap();
        check(&format!("{modes} modes"), &arm, 3 + u64::from(modes));
    }
    let arm = PlanarArm::with_quadrature(crane_links(10), G, 64).unwrap();
    check("10 modes", &arm, 41);
}

#[test]
fn rigid_links_pendulums_and_point_masses_with_rotary_inertia() {
    let arm = PlanarArm::new(crane_links(0), G).unwrap();
    check("rigid crane", &arm, 5);
    let arm = PlanarArm::new(vec![Link::pendulum(6.0, 5000.0).unwrap()], G).unwrap();
    check("pendulum", &arm, 6);
    let pm = |x, mass, inertia| PointMass { x, mass, inertia };
    let links = vec![
        Link::rigid(1.3, 2.0)
            .unwrap()
            .with_rotary_inertia(0.01)
            .unwrap()
            .with_point_mass(pm(0.4, 0.7, 0.05))
            .unwrap(),
        Link::beam(8.0, 210e9, 7850.0, 0.0264, 5.89e-4)
            .unwrap()
            .with_sine_modes(3)
            .unwrap()
            .with_point_mass(pm(3.0, 713.0, 40.0))
            .unwrap()
            .with_point_mass(pm(8.0, 235.0, 0.0))
            .unwrap(),
        Link::pendulum(6.0, 5000.0).unwrap(),
    ];
    let arm = PlanarArm::with_quadrature(links, G, 24).unwrap();
    check("rod, beam with point masses, pendulum", &arm, 7);
}
