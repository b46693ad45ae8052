//! The second derivatives behind the elements' exact partials, against central differences
//! of the first derivatives they differentiate, at random configurations of the flexible
//! knuckle boom: `B = ∂²T/∂u∂q` (columns `(∂M/∂q_k) u`, and `∂E/∂u = Bᵀ`), `H = ∂²T/∂q²`
//! (`∂E/∂q`), `∂²V_g/∂q² = −∂G/∂q`, the Hessian of a point's position and of an actuator's
//! length.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use bg_manipulator::PlanarArm;
use common::{crane, cylinders, Rng};
use nalgebra::{DMatrix, DVector, Vector2};

const H: f64 = 1e-6;

/// Central differences of a vector function along each coordinate: column k = ∂f/∂x_k.
fn jacobian_fd(x: &[f64], f: impl Fn(&[f64]) -> DVector<f64>) -> DMatrix<f64> {
    let n = x.len();
    let m = f(x).len();
    let mut j = DMatrix::zeros(m, n);
    for k in 0..n {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        let h = H * x[k].abs().max(1.0);
        xp[k] += h;
        xm[k] -= h;
        j.set_column(k, &((f(&xp) - f(&xm)) / (2.0 * h)));
    }
    j
}

fn assert_close(name: &str, got: &DMatrix<f64>, want: &DMatrix<f64>) {
    let err = (got - want).abs().max() / want.abs().max().max(1e-300);
    assert!(err < 1e-6, "{name}: relative error {err:e}\n{got}\n{want}");
}

/// Configurations and speeds.
type States = Vec<(Vec<f64>, Vec<f64>)>;

fn arm_and_states(seed: u64) -> (PlanarArm, States) {
    let arm = crane(3);
    let mut rng = Rng::new(seed);
    let _ = rng.vec(16, 1.0); // past the first, tiny draws
    let states = (0..5)
        .map(|_| (rng.q(&arm, 0.2), rng.vec(arm.n(), 1.0)))
        .collect();
    (arm, states)
}

#[test]
fn kinetic_b_and_h_match_differences_of_m_u_and_e() {
    let (arm, states) = arm_and_states(23);
    let n = arm.n();
    for (q, u) in states {
        let (mut b, mut h) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        arm.kinematics(&q).kinetic_partials_into(&u, &mut b, &mut h);
        let uv = DVector::from_column_slice(&u);
        let m_u = jacobian_fd(&q, |q| arm.kinematics(q).mass_matrix() * &uv);
        assert_close("B = ∂(Mu)/∂q", &b, &m_u);
        let de_dq = jacobian_fd(&q, |q| arm.kinematics(q).kinetic_forces(&u));
        assert_close("H = ∂E/∂q", &h, &de_dq);
        let kin = arm.kinematics(&q);
        let de_du = jacobian_fd(&u, |u| kin.kinetic_forces(u));
        assert_close("Bᵀ = ∂E/∂u", &b.transpose(), &de_du);
        assert!((&h - h.transpose()).abs().max() <= 1e-12 * h.abs().max());
    }
}

#[test]
fn gravity_hessian_is_minus_the_derivative_of_g() {
    let (arm, states) = arm_and_states(29);
    let n = arm.n();
    for (q, _) in states {
        let mut h = DMatrix::zeros(n, n);
        arm.kinematics(&q).gravity_hessian_into(&mut h);
        let dg = jacobian_fd(&q, |q| -arm.kinematics(q).gravity_forces());
        assert_close("∂²V_g/∂q²", &h, &dg);
    }
}

#[test]
fn point_and_actuator_length_hessians_match_differences_of_their_gradients() {
    let (arm, states) = arm_and_states(31);
    let n = arm.n();
    let acts = cylinders();
    for (q, _) in states {
        let pose = arm.pose(&q);
        // a point of link 2, with a force
        let s = arm.station(1, 3.3).unwrap();
        let f = Vector2::new(0.7, -1.3);
        let mut got = DMatrix::zeros(n, n);
        pose.point_hessian(&s, |a, b, v| got[(a, b)] += f.dot(&v));
        let want = jacobian_fd(&q, |q| {
            let mut g = DVector::zeros(n);
            arm.pose(q).add_point_force(&s, &f, g.as_mut_slice());
            g
        });
        assert_close("∂²(f·r)/∂q²", &got, &want);
        for act in &acts {
            let (a, b) = (
                arm.resolve_pin(&act.a).unwrap(),
                arm.resolve_pin(&act.b).unwrap(),
            );
            let (mut hess, mut jd) = (DMatrix::zeros(n, n), vec![Vector2::zeros(); n]);
            pose.actuator_length_hessian(&a, &b, &mut jd, &mut hess);
            let want = jacobian_fd(&q, |q| {
                let mut g = DVector::zeros(n);
                let _ = arm.pose(q).actuator_length(&a, &b, g.as_mut_slice());
                g
            });
            assert_close("∇²l", &hess, &want);
        }
    }
}
