//! The arm's elements give exact partial derivatives for the Jacobian: each is checked with
//! the core's `check_partials` against central differences of its own `eval` and
//! `derivatives` (1e-6 relative to the row's scale) at random states of the flexible
//! knuckle boom.
// The arm keeps its frames in a RefCell (shared by its elements on one thread): not Sync.
#![allow(clippy::arc_with_non_send_sync)]
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::sync::Arc;

use bg_manipulator::{
    ActuatorTransformer, ArmCompliance, ArmDamping, ArmInertia, LumpedGravity,
    LumpedMassTransformer,
};
use bondgraph::{check_partials, PortCausality};
use common::{crane, cylinders, initial_pose, lumped_masses, Rng};
use nalgebra::DVector;

use PortCausality::{EffortOut, FlowOut};

/// A generator past its first draws (which are tiny for small seeds: an angle of −π + 1e-8
/// makes a column whose derivative is all rounding).
fn rng(seed: u64) -> Rng {
    let mut r = Rng::new(seed);
    let _ = r.vec(16, 1.0);
    r
}

#[test]
fn the_i_field_gives_exact_partials() {
    let arm = Arc::new(crane(3));
    let n = arm.n();
    let mut rng = rng(41);
    for sign in [1.0, -1.0] {
        let q0 = rng.q(&arm, 0.2);
        let i_field = ArmInertia::new(arm.clone(), q0.clone(), vec![0.0; n]).unwrap();
        let u = DVector::from_vec(rng.vec(n, 1.0));
        let p = arm.kinematics(&q0).mass_matrix() * u;
        // efforts, flows in (written by stage 0), then the states p, q
        let mut point = rng.vec(n, 1e5);
        point.extend(vec![0.0; n]);
        point.extend(p.iter());
        point.extend(&q0);
        let given = check_partials(&i_field, &[(n, sign, FlowOut)], &point);
        // stages 0 (u), 2 (T and geometry), 3 (named coordinates) and the derivatives
        assert_eq!(given, Ok(4));
    }
}

#[test]
fn the_c_field_and_the_r_field_give_exact_partials() {
    let arm = Arc::new(crane(3));
    let n = arm.n();
    let mut rng = rng(43);
    let c = ArmCompliance::new(arm.clone(), "q");
    let mut point = vec![0.0; n];
    point.extend(rng.vec(n, 1.0));
    point.extend(rng.q(&arm, 0.2));
    assert_eq!(check_partials(&c, &[(n, 1.0, EffortOut)], &point), Ok(2));
    let r = ArmDamping::new(rng.vec(n, 1e5).iter().map(|d| d.abs()).collect()).unwrap();
    let mut point = vec![0.0; n];
    point.extend(rng.vec(n, 1.0));
    assert_eq!(check_partials(&r, &[(n, -1.0, EffortOut)], &point), Ok(1));
}

#[test]
fn the_actuator_and_lumped_mass_transformers_give_exact_partials() {
    let arm = Arc::new(crane(3));
    let n = arm.n();
    let mut rng = rng(47);
    let q0 = initial_pose(6);
    for (k, act) in cylinders().into_iter().enumerate() {
        let mtf = ActuatorTransformer::new(arm.clone(), vec![act], "q", &q0)
            .unwrap()
            .numbered_from(k + 1);
        for sign in [1.0, -1.0] {
            // e₁, f_in₁, e₂ (the cylinder force), f_in₂, q
            let mut point = vec![0.0; n];
            point.extend(rng.vec(n, 1.0));
            point.push(2e5 * (k as f64 - 0.5));
            point.push(0.0);
            point.extend(rng.q(&arm, 0.1).iter().zip(&q0).map(|(a, b)| 0.2 * a + b));
            let ports = [(n, sign, EffortOut), (1, -sign, FlowOut)];
            assert_eq!(
                check_partials(&mtf, &ports, &point),
                Ok(4),
                "cylinder {}",
                k + 1
            );
        }
    }
    let pins = lumped_masses().iter().map(|m| m.pin).collect();
    let mtf = LumpedMassTransformer::new(arm.clone(), pins, "q").unwrap();
    let mut point = vec![0.0; n];
    point.extend(rng.vec(n, 1.0));
    point.extend(rng.vec(6, 1e4));
    point.extend(vec![0.0; 6]);
    point.extend(rng.q(&arm, 0.2));
    let ports = [(n, 1.0, EffortOut), (6, -1.0, FlowOut)];
    assert_eq!(check_partials(&mtf, &ports, &point), Ok(2));
    let g = LumpedGravity::new(vec![235.0, 713.0, 235.0], 9.81).unwrap();
    let point = vec![0.0; 12];
    assert_eq!(check_partials(&g, &[(6, 1.0, EffortOut)], &point), Ok(1));
}
