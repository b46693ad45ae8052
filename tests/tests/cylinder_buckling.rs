//! The cylinders' rod check (`<cylinder>_rod_check`, crates/hydraulics/src/buckling.rs) in
//! the knuckle boom crane: its outputs against hand values from docs/knuckle-boom.md
//! (rod d_r = 0.06 m, steel E = 210 GPa, both cylinders on pins) at
//! one time of the luffing run, and its cost: the right-hand side never evaluates it.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use bondgraph::Outcome;

fn crane_with_rod_outputs(t_end: f64) -> Outcome {
    let mut m = bg_tests::load("knuckle_boom", &[]).unwrap();
    // the outputs a user adds to [outputs]
    let extra = [
        ("force1", "cyl1_rod_check.force"),
        ("p_cr1", "cyl1_rod_check.p_cr"),
        ("util1", "cyl1_rod_check.utilisation"),
        ("margin1", "cyl1_rod_check.buckling_margin"),
        ("margin2", "cyl2_rod_check.buckling_margin"),
    ];
    for (name, var) in extra {
        let probe = m.equations.probe(var).unwrap();
        m.outputs.push(bondgraph::Output {
            name: name.to_owned(),
            probe,
        });
    }
    m.settings.t_end = t_end;
    let out = m.run().unwrap();
    assert!(out.error.is_none(), "{:?}", out.error);
    out
}

#[test]
fn crane_rod_margin_equals_the_hand_euler_value() {
    let out = crane_with_rod_outputs(10.0);
    let col = |n: &str| out.trajectory.column(n).unwrap();
    // the cylinder's own length l = l0 + s (l0 = 3.5 m); the arm's pin distance `l1` agrees
    // with it up to the integration error
    let (t, s1, f1) = (col("t"), col("s1"), col("F_c1"));
    let l1: Vec<f64> = s1.iter().map(|s| 3.5 + s).collect();
    let pins = col("l1");
    let (force, p_cr, util, margin) = (col("force1"), col("p_cr1"), col("util1"), col("margin1"));
    // d_r = 0.06: I = π d⁴/64 = 6.3617e-7 m⁴; pinned–pinned, L = the current length l1
    let i = PI * 0.06_f64.powi(4) / 64.0;
    let k = t.iter().position(|&x| (x - 10.0).abs() < 1e-9).unwrap();
    let hand = PI * PI * 210e9 * i / (l1[k] * l1[k]);
    assert!(
        ((p_cr[k] - hand) / hand).abs() < 1e-12,
        "{} vs {hand}",
        p_cr[k]
    );
    // no end stop in the crane: the rod force is the cylinder force F_c
    assert!((force[k] - f1[k]).abs() <= 1e-9 * f1[k].abs());
    assert!(((margin[k] - hand / f1[k]) / margin[k]).abs() < 1e-12);
    assert!(((util[k] * margin[k]) - 1.0).abs() < 1e-12);
    // the numbers at t = 10 s: l = 5.950 m, P_E = 37.24 kN, F_c1 = 666 kN (the scene's rigid
    // hold figure is 512 kN at l = 6.0), so the margin is 0.056, far below one: a 60 mm rod
    // taken pinned over the whole pin distance would buckle (docs/fatigue.md, "Cylinder
    // checks")
    eprintln!(
        "t = {}: l1 = {:.4} m, F_c1 = {:.1} kN, P_E = {:.2} kN, margin = {:.4}",
        t[k],
        l1[k],
        f1[k] / 1e3,
        p_cr[k] / 1e3,
        margin[k]
    );
    assert!((5.5..6.1).contains(&l1[k]), "{}", l1[k]);
    assert!((l1[k] - pins[k]).abs() < 1e-6, "{} vs {}", l1[k], pins[k]);
    assert!((30e3..45e3).contains(&p_cr[k]), "{}", p_cr[k]);
    assert!((0.05..0.1).contains(&margin[k]), "{}", margin[k]);
    // cylinder 2 pulls at first (F_c2 < 0 holds the knuckle): its margin is the cap there
    let m2 = col("margin2");
    assert!(m2.iter().all(|v| v.is_finite() && *v > 0.0));
}

#[test]
fn the_right_hand_side_does_not_evaluate_the_rod_check() {
    let m = bg_tests::load("knuckle_boom", &[]).unwrap();
    let eqs = &m.equations;
    let probe = eqs.probe("cyl1_rod_check.buckling_margin").unwrap();
    let force = eqs.probe("cyl1_piston.mech.e").unwrap();
    let mut dx = vec![0.0; m.x0.len()];
    eqs.forget();
    eqs.rhs(0.0, &m.x0, &mut dx);
    assert!(
        eqs.read(force, 0.0, &m.x0).is_finite(),
        "rhs computes the force"
    );
    assert!(
        eqs.read(probe, 0.0, &m.x0).is_nan(),
        "rhs left the rod check alone"
    );
    // and a whole evaluation (what an output row asks for) does compute it
    eqs.evaluate(0.0, &m.x0);
    assert!(eqs.read(probe, 0.0, &m.x0).is_finite());
}
