//! Reference models with analytic (or independently computed) solutions: mass–spring–damper
//! for every integration method, series RLC step response, a two-mass lever, a DC motor and a
//! lever whose ratio is modulated by a displacement.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use approx::assert_abs_diff_eq;
use bondgraph::*;
use common::*;

/// Largest |a − b| over paired samples.
fn max_abs_diff(a: impl IntoIterator<Item = f64>, b: impl IntoIterator<Item = f64>) -> f64 {
    a.into_iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// m = 1, k = 100 (c = 1/k), r = 0.4, q0 = 0.01, no force: m·x'' + r·x' + k·x = 0 with
/// α = r/2m = 0.2, ω0 = 10, ω_d = √(ω0² − α²). Position (spring.q) compared with the analytic
/// solution at every output row (dt_out = 0.01) over 10 s (16 periods).
///
/// At rtol 1e-8, atol 1e-12 every method runs; BDF (orders 1–5), Tsit45 (order 5) and
/// Radau IIA (order 5) stay within 1e-6 of the amplitude (1e-8 absolute); Radau is held to
/// 1e-8 of it (it measures 1.25e-9). ESDIRK34 (order 3) and TR-BDF2 (order 2)
/// cannot at that tolerance: local error control lets the global error grow with the number
/// of steps, and they measure about 2.6e-6 and 8.6e-6 of the amplitude there (their errors
/// shrink as tol^(3/4) and tol^(2/3) when atol is also lowered, so this is their order, not
/// a defect). They are held to bounds about twice their measured error at rtol 1e-8 (5e-6,
/// 2e-5), and to the 1e-6 requirement at the tighter rtol that reaches it (ESDIRK34 at 1e-9,
/// TR-BDF2 at 1e-10: about 4.5e-7 of the amplitude).
#[test]
fn mass_spring_damper_matches_analytic_for_every_method() {
    let (m, k, r, q0): (f64, f64, f64, f64) = (1.0, 100.0, 0.4, 0.01);
    let (alpha, omega0) = (r / (2.0 * m), (k / m).sqrt());
    // (method, rtol, atol, bound on |x − x_exact| relative to q0)
    let cases = [
        (Method::Bdf, 1e-8, 1e-12, 1e-6),
        (Method::Esdirk34, 1e-8, 1e-12, 5e-6),
        (Method::TrBdf2, 1e-8, 1e-12, 2e-5),
        (Method::Tsit45, 1e-8, 1e-12, 1e-6),
        (Method::Radau5, 1e-8, 1e-12, 1e-8), // measured 1.25e-9
        (Method::Esdirk34, 1e-9, 1e-14, 1e-6),
        (Method::TrBdf2, 1e-10, 1e-14, 1e-6),
    ];
    for method in Method::ALL {
        assert!(
            cases
                .iter()
                .any(|c| c.0 == method && (c.1 - 1e-8f64).abs() < 1e-20),
            "{} not run at rtol 1e-8",
            method.name()
        );
    }
    for (method, rtol, atol, bound) in cases {
        let mut eqs = mass_spring_damper(m, k, r, q0);
        let x0 = eqs.initial_state();
        let outs = [output(&eqs, "spring.q"), output(&eqs, "mass.p")];
        let run = simulate(
            &mut eqs,
            &x0,
            &settings(method, 10.0, 0.01, rtol, atol),
            &outs,
            vec![],
        );
        let name = format!("{} (rtol {rtol:e}, atol {atol:e})", method.name());
        eprintln!("mass-spring-damper, {name}: {}", run.stats);
        assert!(run.error.is_none(), "{name}: {:?}", run.error);
        let t = col(&run.trajectory, "t");
        assert_eq!(t.len(), 1001, "{name}: rows");
        let exact = |t: f64| underdamped(q0, 0.0, alpha, omega0, t);
        let err_x = max_abs_diff(
            col(&run.trajectory, "spring.q"),
            t.iter().map(|&t| exact(t).0),
        );
        let err_p = max_abs_diff(
            col(&run.trajectory, "mass.p"),
            t.iter().map(|&t| m * exact(t).1),
        );
        eprintln!(
            "  max |x − x_exact| = {err_x:.3e} ({:.2e} of q0), max |p − p_exact| = {err_p:.3e}",
            err_x / q0
        );
        assert!(
            err_x <= bound * q0,
            "{name}: position error {err_x:e} > {:e}",
            bound * q0
        );
        // The momentum amplitude is ω0·m·q0 = 0.1.
        assert!(
            err_p <= bound * omega0 * m * q0,
            "{name}: momentum error {err_p:e}"
        );
        // The final state is the analytic one too.
        assert_abs_diff_eq!(run.t_final, 10.0, epsilon = 1e-12);
        assert_abs_diff_eq!(
            run.x_final[state_index(&eqs, "spring.q")],
            exact(10.0).0,
            epsilon = bound * q0
        );
        assert!(run.stats.steps > 0 && run.stats.rhs_evals >= run.stats.steps);
    }
}

fn state_index(eqs: &StateEquations, name: &str) -> usize {
    eqs.states()
        .iter()
        .position(|s| s.name == name)
        .unwrap_or_else(|| panic!("no state {name}"))
}

/// Series RLC, V = 2, R = 1, L = 1, C = 0.25, at rest: L·q'' + R·q' + q/C = V. With
/// y = q − C·V: y'' + 2α·y' + ω0²·y = 0, α = R/2L = 0.5, ω0 = 1/√(LC) = 2, y(0) = −CV,
/// y'(0) = 0, so v_C = q/C = V·(1 − e^{−αt}(cos ω_d t + α/ω_d sin ω_d t)).
#[test]
fn series_rlc_capacitor_voltage_matches_step_response() {
    let (v, r, l, c): (f64, f64, f64, f64) = (2.0, 1.0, 1.0, 0.25);
    let (alpha, omega0) = (r / (2.0 * l), 1.0 / (l * c).sqrt());
    let mut eqs = series_rlc(v, r, l, c);
    let x0 = eqs.initial_state();
    let outs = [
        output(&eqs, "C.e"),
        output(&eqs, "L.f"),
        output(&eqs, "R.e"),
    ];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 20.0, 0.01, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let t = col(&run.trajectory, "t");
    let exact_vc = t
        .iter()
        .map(|&t| v + underdamped(-c * v, 0.0, alpha, omega0, t).0 / c);
    let exact_i = t
        .iter()
        .map(|&t| underdamped(-c * v, 0.0, alpha, omega0, t).1);
    let err_vc = max_abs_diff(col(&run.trajectory, "C.e"), exact_vc);
    let err_i = max_abs_diff(col(&run.trajectory, "L.f"), exact_i);
    assert!(err_vc <= 1e-6 * v, "capacitor voltage error {err_vc:e}");
    assert!(err_i <= 1e-6 * v / r, "current error {err_i:e}");
    // Ohm's law on the resistor bond at every row, and the final value V.
    for (e_r, i) in col(&run.trajectory, "R.e")
        .into_iter()
        .zip(col(&run.trajectory, "L.f"))
    {
        assert_abs_diff_eq!(e_r, r * i, epsilon = 1e-12);
    }
    assert_abs_diff_eq!(
        *col(&run.trajectory, "C.e").last().unwrap(),
        v,
        epsilon = 1e-3 * v
    );
}

/// Two masses coupled through a lever (TF, ratio n): `m1` on side 1, the lever's side 2
/// (velocity n·v1) pushes `m2` through a spring k. A *rigid* coupling of the two masses would
/// be derivative causality (tested in `causality.rs`), hence the spring between them.
///
/// Reduced system: the TF law e1 = n·e2, f2 = n·f1 makes side 2 see m1 as m1/n²
/// (½·m1·v1² = ½·(m1/n²)·(n·v1)²; seen from side 1, m2 would weigh m2·n², the usual
/// m_eff = m1 + n²·m2 when rigid). The spring sits between the reflected mass m1/n² and m2,
/// so its deflection q (q' = n·v1 − v2) obeys q'' = −k·q·(n²/m1 + 1/m2): one oscillation
/// mode with ω² = k/μ, μ = (m1/n²)·m2/(m1/n² + m2), and q(t) = q0·cos ωt from rest. The
/// generalised momentum p1 + n·p2 is conserved (dp1/dt = −n·F, dp2/dt = F), and so is the
/// energy without damping.
#[test]
fn lever_two_masses_oscillate_at_reduced_mass_frequency_and_conserve_energy() {
    let (n, m1, m2, k, q0): (f64, f64, f64, f64, f64) = (2.0, 3.0, 0.5, 40.0, 0.02);
    let m1_reflected = m1 / (n * n);
    let mu = m1_reflected * m2 / (m1_reflected + m2);
    let omega = (k / mu).sqrt();
    let mut eqs = lever(Transformer::new(n).unwrap(), m1, m2, k, q0, None);
    let x0 = eqs.initial_state();
    let e0 = eqs.stored_energy(&x0);
    assert_abs_diff_eq!(e0, 0.5 * k * q0 * q0, epsilon = 1e-15);
    let outs = [
        output(&eqs, "spring.q"),
        output(&eqs, "m1.p"),
        output(&eqs, "m2.p"),
        output(&eqs, "m1.f"),
        output(&eqs, "m2.f"),
    ];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 3.0, 0.005, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let tr = &run.trajectory;
    let t = col(tr, "t");
    let err_q = max_abs_diff(
        col(tr, "spring.q"),
        t.iter().map(|&t| q0 * (omega * t).cos()),
    );
    assert!(
        err_q <= 1e-6 * q0,
        "spring deflection error {err_q:e} (ω = {omega})"
    );
    let (p1, p2) = (col(tr, "m1.p"), col(tr, "m2.p"));
    let p_scale = (k * q0 * q0 * m2).sqrt(); // momentum scale √(2·E·m)
    for (a, b) in p1.iter().zip(&p2) {
        assert_abs_diff_eq!(a + n * b, 0.0, epsilon = 1e-7 * p_scale);
    }
    // The flow on m1's bond is its velocity p1/m1.
    let v1 = col(tr, "m1.f");
    assert!(max_abs_diff(v1.iter().copied(), p1.iter().map(|p| p / m1)) <= 1e-15);
    // Energy over the run, from the recorded states.
    let x_index = ["m1.p", "spring.q", "m2.p"].map(|s| state_index(&eqs, s));
    let cols = [col(tr, "m1.p"), col(tr, "spring.q"), col(tr, "m2.p")];
    let mut x = vec![0.0; eqs.n_states()];
    for row in 0..t.len() {
        for (j, &i) in x_index.iter().enumerate() {
            x[i] = cols[j][row];
        }
        let e = eqs.stored_energy(&x);
        assert!(
            ((e - e0) / e0).abs() <= 1e-6,
            "energy drift {:e} at t = {}",
            (e - e0) / e0,
            t[row]
        );
    }
}

/// DC motor without inductance: V → R_a → GY(k) → J, b. Current i = (V − k·ω)/R_a,
/// J·ω' = k·i − b·ω = k·V/R_a − (k²/R_a + b)·ω, so ω(t) = ω_ss·(1 − e^{−t/τ}) with
/// ω_ss = k·V/(k² + R_a·b) and τ = J·R_a/(k² + R_a·b).
#[test]
fn dc_motor_speed_is_first_order_with_analytic_time_constant() {
    let (v, ra, k, j, b) = (12.0, 2.0, 0.5, 0.01, 0.1);
    let w_ss = k * v / (k * k + ra * b);
    let tau = j * ra / (k * k + ra * b);
    let mut eqs = dc_motor(v, ra, None, k, j, b);
    let x0 = eqs.initial_state();
    let outs = [
        output(&eqs, "J.f"),
        output(&eqs, "Ra.f"),
        output(&eqs, "gy.2.e"),
    ];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 1.0, 0.001, 1e-10, 1e-12),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let tr = &run.trajectory;
    let t = col(tr, "t");
    let w = col(tr, "J.f");
    let err = max_abs_diff(
        w.iter().copied(),
        t.iter().map(|&t| w_ss * (1.0 - (-t / tau).exp())),
    );
    assert!(err <= 1e-7 * w_ss, "speed error {err:e}");
    // Steady speed after 1 s ≈ 22 τ.
    assert_abs_diff_eq!(*w.last().unwrap(), w_ss, epsilon = 1e-7 * w_ss);
    // The time constant read back from the trajectory at t ≈ τ, 2τ, 3τ.
    for (&ti, &wi) in t
        .iter()
        .zip(&w)
        .filter(|(&ti, _)| ti > 0.5 * tau && ti < 3.0 * tau)
    {
        let tau_est = -ti / (1.0 - wi / w_ss).ln();
        assert!(
            ((tau_est - tau) / tau).abs() <= 1e-5,
            "τ estimate {tau_est} at t = {ti}, expected {tau}"
        );
    }
    // Gyrator law along the run: torque = k·i (i = current through R_a).
    for (torque, i) in col(tr, "gy.2.e").into_iter().zip(col(tr, "Ra.f")) {
        assert_abs_diff_eq!(torque, k * i, epsilon = 1e-12 * k * v / ra);
    }
}

/// DC motor with armature inductance: the same steady speed k·V/(k² + R_a·b).
#[test]
fn dc_motor_with_inductance_reaches_the_same_steady_speed() {
    let (v, ra, la, k, j, b) = (12.0, 2.0, 0.01, 0.5, 0.01, 0.1);
    let w_ss = k * v / (k * k + ra * b);
    let i_ss = (v - k * w_ss) / ra;
    let mut eqs = dc_motor(v, ra, Some(la), k, j, b);
    let x0 = eqs.initial_state();
    let outs = [output(&eqs, "J.f"), output(&eqs, "La.f")];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 1.5, 0.01, 1e-10, 1e-12),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    assert_abs_diff_eq!(
        *col(&run.trajectory, "J.f").last().unwrap(),
        w_ss,
        epsilon = 1e-6 * w_ss
    );
    assert_abs_diff_eq!(
        *col(&run.trajectory, "La.f").last().unwrap(),
        i_ss,
        epsilon = 1e-6 * v / ra
    );
}

/// Lever with the modulated ratio n(q) = 1 + q (q = spring.q). An independent RK4 of
///   p1' = −n·F, q' = n·p1/m1 − p2/m2, p2' = F, F = k·q,
/// with a small fixed step is the reference. The MTF conserves power, so without damping the
/// stored energy is conserved although the ratio varies.
#[test]
fn modulated_lever_matches_reference_ode_and_conserves_energy() {
    let (m1, m2, k, q0) = (1.5, 0.5, 40.0, 0.05); // as in common::modulated_lever
    let mut eqs = modulated_lever(None);
    assert_eq!(
        eqs.graph()
            .node(eqs.graph().find("tf").unwrap())
            .element
            .kind(),
        "MTF"
    );
    let x0 = eqs.initial_state();
    let e0 = eqs.stored_energy(&x0);
    let outs = [
        output(&eqs, "m1.p"),
        output(&eqs, "spring.q"),
        output(&eqs, "m2.p"),
    ];
    let t_end = 2.0;
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, t_end, 0.01, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    assert_eq!(run.trajectory.rows.len(), 201);

    let f = |y: [f64; 3]| {
        let (p1, q, p2) = (y[0], y[1], y[2]);
        let (n, force) = (1.0 + q, k * q);
        [-n * force, n * p1 / m1 - p2 / m2, force]
    };
    let h = 1e-4;
    let mut y = [0.0, q0, 0.0];
    let mut reference = vec![y];
    let steps_per_row = 100;
    for _ in 0..(t_end / 0.01).round() as usize {
        for _ in 0..steps_per_row {
            let k1 = f(y);
            let k2 = f(std::array::from_fn(|i| y[i] + 0.5 * h * k1[i]));
            let k3 = f(std::array::from_fn(|i| y[i] + 0.5 * h * k2[i]));
            let k4 = f(std::array::from_fn(|i| y[i] + h * k3[i]));
            y = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        reference.push(y);
    }
    let tr = &run.trajectory;
    let p_scale = (2.0 * e0 * m1).sqrt();
    for (name, i, scale) in [
        ("m1.p", 0, p_scale),
        ("spring.q", 1, q0),
        ("m2.p", 2, p_scale),
    ] {
        let err = max_abs_diff(col(tr, name), reference.iter().map(|r| r[i]));
        assert!(
            err <= 1e-6 * scale,
            "{name}: error {err:e} against RK4 (scale {scale})"
        );
    }
    let e_end = eqs.stored_energy(&run.x_final);
    assert!(
        ((e_end - e0) / e0).abs() <= 1e-6,
        "energy drift {:e}",
        (e_end - e0) / e0
    );
}

/// The lever the other way round: the mass (m) on side 2 sets the flow, so the TF runs in its
/// inverse orientation (e2 = e1/n, f1 = f2/n). The spring on side 1 moves at v1 = v2/n, the
/// mass feels the spring force divided by n: q'' = −k·q/(n²·m), ω = √(k/(n²·m)).
#[test]
fn transformer_in_inverse_orientation_scales_the_spring() {
    let (n, m, k, q0): (f64, f64, f64, f64) = (0.5, 2.0, 30.0, 0.03);
    let omega = (k / (n * n * m)).sqrt();
    let mut eqs = reversed_lever(n, m, k, q0);
    let tf = eqs.graph().find("tf").unwrap();
    let causal: Vec<PortCausality> = (0..2)
        .map(|p| {
            if eqs.effort_setter()[eqs.graph().ports_of(tf)[p].unwrap()] == tf {
                PortCausality::EffortOut
            } else {
                PortCausality::FlowOut
            }
        })
        .collect();
    assert_eq!(
        causal,
        [PortCausality::FlowOut, PortCausality::EffortOut],
        "inverse orientation"
    );
    let x0 = eqs.initial_state();
    let outs = [
        output(&eqs, "spring.q"),
        output(&eqs, "tf.1.e"),
        output(&eqs, "tf.2.e"),
        output(&eqs, "tf.1.f"),
        output(&eqs, "tf.2.f"),
    ];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 2.0, 0.01, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let tr = &run.trajectory;
    let t = col(tr, "t");
    let err = max_abs_diff(
        col(tr, "spring.q"),
        t.iter().map(|&t| q0 * (omega * t).cos()),
    );
    assert!(err <= 1e-6 * q0, "spring error {err:e}");
    let (e1, e2, f1, f2) = (
        col(tr, "tf.1.e"),
        col(tr, "tf.2.e"),
        col(tr, "tf.1.f"),
        col(tr, "tf.2.f"),
    );
    for i in 0..t.len() {
        assert_abs_diff_eq!(e1[i], n * e2[i], epsilon = 1e-12 * k * q0);
        assert_abs_diff_eq!(f2[i], n * f1[i], epsilon = 1e-12);
    }
}

/// Two capacitors coupled by a gyrator in admittance causality: q1' = −q2/(c2·r),
/// q2' = q1/(c1·r), so q1 = q10·cos ωt, q2 = q10/(c1·r·ω)·sin ωt with ω = 1/(r·√(c1·c2)),
/// and the stored energy is conserved.
#[test]
fn gyrator_in_admittance_causality_couples_two_capacitors() {
    let (r, c1, c2, q10): (f64, f64, f64, f64) = (2.0, 0.5, 0.125, 0.1);
    let omega = 1.0 / (r * (c1 * c2).sqrt());
    let mut eqs = gyrator_between_capacitors(r, c1, c2, q10);
    let gy = eqs.graph().find("gy").unwrap();
    let setters = eqs.effort_setter();
    assert!(
        eqs.graph()
            .ports_of(gy)
            .iter()
            .all(|b| setters[b.unwrap()] != gy),
        "GY in admittance causality"
    );
    let x0 = eqs.initial_state();
    let e0 = eqs.stored_energy(&x0);
    let outs = [output(&eqs, "C1.q"), output(&eqs, "C2.q")];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 5.0, 0.01, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let tr = &run.trajectory;
    let t = col(tr, "t");
    let err1 = max_abs_diff(col(tr, "C1.q"), t.iter().map(|&t| q10 * (omega * t).cos()));
    let err2 = max_abs_diff(
        col(tr, "C2.q"),
        t.iter()
            .map(|&t| q10 / (c1 * r * omega) * (omega * t).sin()),
    );
    assert!(
        err1 <= 1e-6 * q10 && err2 <= 1e-6 * q10,
        "errors {err1:e}, {err2:e}"
    );
    let e_end = eqs.stored_energy(&run.x_final);
    assert!(
        ((e_end - e0) / e0).abs() <= 1e-6,
        "energy drift {:e}",
        (e_end - e0) / e0
    );
}

/// A planar mass on a spring along the unit direction u = (0.6, 0.8), through a constant 2×1
/// matrix MTF: e1 = u·F, spring rate q' = uᵀv. Along u it oscillates with ω = √(k/m):
/// q = q0·cos ωt + uᵀp0/(m·ω)·sin ωt; across u its momentum p⊥ = p − u·uᵀp stays p⊥(0).
#[test]
fn matrix_transformer_projects_a_planar_mass_onto_a_spring() {
    let (m, k, q0): (f64, f64, f64) = (2.0, 50.0, 0.02);
    let p0 = [0.3, -0.2];
    let u = [0.6, 0.8];
    let omega = (k / m).sqrt();
    let up0 = u[0] * p0[0] + u[1] * p0[1];
    let p_perp = [p0[0] - u[0] * up0, p0[1] - u[1] * up0];
    let mut eqs = planar_constant_mtf(m, k, p0, q0);
    let x0 = eqs.initial_state();
    let outs = [
        output(&eqs, "spring.q"),
        output(&eqs, "mass.p[0]"),
        output(&eqs, "mass.p[1]"),
    ];
    let run = simulate(
        &mut eqs,
        &x0,
        &settings(Method::Bdf, 3.0, 0.01, 1e-10, 1e-13),
        &outs,
        vec![],
    );
    assert!(run.error.is_none(), "{:?}", run.error);
    let tr = &run.trajectory;
    let t = col(tr, "t");
    let q_exact = |t: f64| q0 * (omega * t).cos() + up0 / (m * omega) * (omega * t).sin();
    let err_q = max_abs_diff(col(tr, "spring.q"), t.iter().map(|&t| q_exact(t)));
    assert!(
        err_q <= 1e-6 * q0.max(up0.abs() / (m * omega)),
        "spring error {err_q:e}"
    );
    let (pa, pb) = (col(tr, "mass.p[0]"), col(tr, "mass.p[1]"));
    for i in 0..t.len() {
        // uᵀp = m·q'.
        let up = m * (-q0 * omega * (omega * t[i]).sin() + up0 / m * (omega * t[i]).cos());
        assert_abs_diff_eq!(pa[i], p_perp[0] + u[0] * up, epsilon = 1e-6);
        assert_abs_diff_eq!(pb[i], p_perp[1] + u[1] * up, epsilon = 1e-6);
    }
}
