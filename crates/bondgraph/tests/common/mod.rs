//! Reference models and analytic solutions shared by the integration tests.
//!
//! Every builder goes through the public API only (`BondGraph::add`, `connect_names`,
//! `connect`, `assign_causality`, `StateEquations::new`) and returns the assembled equations.
//! Each test binary uses a subset, hence the `dead_code` allowance.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use bondgraph::*;

/// Assign causality and assemble, panicking with the error's message on failure.
pub fn assemble(g: BondGraph) -> StateEquations {
    let causal = assign_causality(g).unwrap_or_else(|e| panic!("causality: {e}"));
    StateEquations::new(causal).unwrap_or_else(|e| panic!("equations: {e}"))
}

/// Connect a list of `from -> to` name pairs.
pub fn bond_all(g: &mut BondGraph, pairs: &[(&str, &str)]) {
    for (from, to) in pairs {
        g.connect_names(from, to)
            .unwrap_or_else(|e| panic!("{from} -> {to}: {e}"));
    }
}

/// An output column reading `probe`.
pub fn output(eqs: &StateEquations, name: &str) -> Output {
    Output {
        name: name.to_owned(),
        probe: eqs
            .probe(name)
            .unwrap_or_else(|| panic!("no probe `{name}`")),
    }
}

/// Index of a named column of a trajectory.
pub fn col(traj: &Trajectory, name: &str) -> Vec<f64> {
    traj.column(name)
        .unwrap_or_else(|| panic!("no column `{name}` in {:?}", traj.columns))
}

/// Free response of x'' + 2αx' + ω0²x = 0 from (x0, v0), for α < ω0 (underdamped or
/// undamped): returns (x(t), x'(t)).
///
/// x(t) = e^{−αt}·(x0·cos ω_d t + B·sin ω_d t), B = (v0 + α·x0)/ω_d, ω_d = √(ω0² − α²).
pub fn underdamped(x0: f64, v0: f64, alpha: f64, omega0: f64, t: f64) -> (f64, f64) {
    assert!(alpha < omega0, "not underdamped");
    let wd = (omega0 * omega0 - alpha * alpha).sqrt();
    let b = (v0 + alpha * x0) / wd;
    let (s, c) = (wd * t).sin_cos();
    let decay = (-alpha * t).exp();
    let x = decay * (x0 * c + b * s);
    let v = decay * (-alpha * (x0 * c + b * s) + (-x0 * wd * s + b * wd * c));
    (x, v)
}

/// Mass–spring–damper: `v` (1-junction) with `mass` (I, m), `spring` (C, 1/k, q0) and
/// `damper` (R, r). Position = `spring.q`, momentum = `mass.p`.
///
/// The 1-junction gives e_mass + e_spring + e_damper = 0, i.e. m·x'' = −k·x − r·x'.
pub fn mass_spring_damper(m: f64, k: f64, r: f64, q0: f64) -> StateEquations {
    let mut g = BondGraph::new();
    g.add("v", OneJunction).unwrap();
    g.add("mass", Inertia::new(m, 0.0).unwrap()).unwrap();
    g.add("spring", Capacitor::new(1.0 / k, q0).unwrap())
        .unwrap();
    g.add("damper", Resistor::new(r).unwrap()).unwrap();
    bond_all(&mut g, &[("v", "mass"), ("v", "spring"), ("v", "damper")]);
    assemble(g)
}

/// Series RLC circuit: `src` (Se, V) → `loop` (1-junction) with `L` (I), `R` (R), `C` (C),
/// all initially at rest. KVL: V = L·i' + R·i + q/C.
pub fn series_rlc(v: f64, r: f64, l: f64, c: f64) -> StateEquations {
    let mut g = BondGraph::new();
    g.add("src", EffortSource::new(v)).unwrap();
    g.add("loop", OneJunction).unwrap();
    g.add("L", Inertia::new(l, 0.0).unwrap()).unwrap();
    g.add("R", Resistor::new(r).unwrap()).unwrap();
    g.add("C", Capacitor::new(c, 0.0).unwrap()).unwrap();
    bond_all(
        &mut g,
        &[("src", "loop"), ("loop", "L"), ("loop", "R"), ("loop", "C")],
    );
    assemble(g)
}

/// Lever: mass `m1` on `j1` (1-junction, velocity v1) drives the lever `tf` (port 1), whose
/// port 2 (velocity n·v1) pushes through `spring` (C on the 0-junction `z`) the mass `m2` on
/// `j2`. An optional `damper` on `j1`. Initial spring deflection `q0`, masses at rest.
///
/// Port numbers are given explicitly with `connect((id, Some(port)), …)`.
pub fn lever(
    tf: Transformer,
    m1: f64,
    m2: f64,
    k: f64,
    q0: f64,
    damping: Option<f64>,
) -> StateEquations {
    let mut g = BondGraph::new();
    let j1 = g.add("j1", OneJunction).unwrap();
    let i1 = g.add("m1", Inertia::new(m1, 0.0).unwrap()).unwrap();
    let t = g.add("tf", tf).unwrap();
    let z = g.add("z", ZeroJunction).unwrap();
    let c = g
        .add("spring", Capacitor::new(1.0 / k, q0).unwrap())
        .unwrap();
    let j2 = g.add("j2", OneJunction).unwrap();
    let i2 = g.add("m2", Inertia::new(m2, 0.0).unwrap()).unwrap();
    g.connect((j1, None), (i1, Some(0))).unwrap();
    g.connect((j1, None), (t, Some(0))).unwrap();
    g.connect((t, Some(1)), (z, None)).unwrap();
    g.connect((z, None), (c, Some(0))).unwrap();
    g.connect((z, None), (j2, None)).unwrap();
    g.connect((j2, None), (i2, Some(0))).unwrap();
    if let Some(r) = damping {
        let d = g.add("damper", Resistor::new(r).unwrap()).unwrap();
        g.connect((j1, None), (d, Some(0))).unwrap();
    }
    assemble(g)
}

/// DC motor: `V` (Se) → `elec` (1-junction) with `Ra` (R) [and `La` (I)] → `gy` (GY, k) →
/// `mech` (1-junction) with `J` (I) and `b` (R, friction). Rotor speed = `J.f`.
pub fn dc_motor(
    v: f64,
    ra: f64,
    la: Option<f64>,
    k: impl Into<Param>,
    j: f64,
    b: f64,
) -> StateEquations {
    let mut g = BondGraph::new();
    g.add("V", EffortSource::new(v)).unwrap();
    g.add("elec", OneJunction).unwrap();
    g.add("Ra", Resistor::new(ra).unwrap()).unwrap();
    g.add("gy", Gyrator::new(k).unwrap()).unwrap();
    g.add("mech", OneJunction).unwrap();
    g.add("J", Inertia::new(j, 0.0).unwrap()).unwrap();
    g.add("b", Resistor::new(b).unwrap()).unwrap();
    bond_all(
        &mut g,
        &[
            ("V", "elec"),
            ("elec", "Ra"),
            ("elec", "gy"),
            ("gy", "mech"),
            ("mech", "J"),
            ("mech", "b"),
        ],
    );
    if let Some(l) = la {
        g.add("La", Inertia::new(l, 0.0).unwrap()).unwrap();
        bond_all(&mut g, &[("elec", "La")]);
    }
    assemble(g)
}

/// The lever with a modulated ratio m = 1 + spring.q (an MTF reading a displacement).
pub fn modulated_lever(damping: Option<f64>) -> StateEquations {
    let tf =
        Transformer::new(Param::modulated(vec!["spring.q".into()], |_, u| 1.0 + u[0])).unwrap();
    lever(tf, 1.5, 0.5, 40.0, 0.05, damping)
}

/// A planar point mass (`mass`, I on a 2-bond, 1-junction `jm` of dimension 2) tied to ground
/// by a scalar `spring` through a 2×1 matrix MTF whose column depends on `spring.q`, plus a
/// scalar `damper` on the spring's 0-junction `z`.
pub fn planar_matrix_mtf() -> StateEquations {
    let mut g = BondGraph::new();
    let jm = g.add("jm", OneJunction).unwrap();
    let mass = g
        .add("mass", Inertia::multi(2.0, vec![0.3, -0.2]).unwrap())
        .unwrap();
    // nalgebra is not a dev-dependency: the matrix type is inferred from `MatrixTransformer::new`.
    let mtf = MatrixTransformer::new(
        2,
        1,
        vec![SignalSpec::scalar("spring.q")],
        boxed_law(|io, t| {
            let q = io.u(0);
            set(t, (0, 0), (0.6 + q).cos());
            set(t, (1, 0), (0.6 + q).sin());
        }),
    )
    .unwrap();
    let mtf = g.add("mtf", mtf).unwrap();
    let z = g.add("z", ZeroJunction).unwrap();
    let c = g
        .add("spring", Capacitor::new(0.05, 0.01).unwrap())
        .unwrap();
    let d = g.add("damper", Resistor::new(0.7).unwrap()).unwrap();
    g.connect((jm, None), (mass, Some(0))).unwrap();
    g.connect((jm, None), (mtf, Some(0))).unwrap();
    g.connect((mtf, Some(1)), (z, None)).unwrap();
    g.connect((z, None), (c, Some(0))).unwrap();
    g.connect((z, None), (d, Some(0))).unwrap();
    assemble(g)
}

/// A lever used the other way round: `spring` (C, 1/k) on `j1` at side 1, `mass` (I, m) on
/// `j2` at side 2 of `tf` (ratio n). The mass sets the flow of side 2, so the TF computes
/// e2 = e1/n and f1 = f2/n (its inverse orientation).
pub fn reversed_lever(n: f64, m: f64, k: f64, q0: f64) -> StateEquations {
    let mut g = BondGraph::new();
    let j1 = g.add("j1", OneJunction).unwrap();
    let c = g
        .add("spring", Capacitor::new(1.0 / k, q0).unwrap())
        .unwrap();
    let t = g.add("tf", Transformer::new(n).unwrap()).unwrap();
    let j2 = g.add("j2", OneJunction).unwrap();
    let i = g.add("mass", Inertia::new(m, 0.0).unwrap()).unwrap();
    g.connect((j1, None), (c, Some(0))).unwrap();
    g.connect((j1, None), (t, Some(0))).unwrap();
    g.connect((t, Some(1)), (j2, None)).unwrap();
    g.connect((j2, None), (i, Some(0))).unwrap();
    assemble(g)
}

/// Two compliances coupled by a gyrator (modulus r): `C1` on `z1`, `C2` on `z2`, both setting
/// their efforts, so the GY is in admittance causality (f_in2 = −e1/r, f_in1 = e2/r).
pub fn gyrator_between_capacitors(r: f64, c1: f64, c2: f64, q10: f64) -> StateEquations {
    let mut g = BondGraph::new();
    g.add("z1", ZeroJunction).unwrap();
    g.add("C1", Capacitor::new(c1, q10).unwrap()).unwrap();
    g.add("gy", Gyrator::new(r).unwrap()).unwrap();
    g.add("z2", ZeroJunction).unwrap();
    g.add("C2", Capacitor::new(c2, 0.0).unwrap()).unwrap();
    bond_all(
        &mut g,
        &[("z1", "C1"), ("z1", "gy"), ("gy", "z2"), ("z2", "C2")],
    );
    assemble(g)
}

/// A planar point mass (m, initial momentum `p0`) on a spring (k) acting along the fixed unit
/// direction u = (0.6, 0.8), through a constant 2×1 matrix MTF T = u.
pub fn planar_constant_mtf(m: f64, k: f64, p0: [f64; 2], q0: f64) -> StateEquations {
    let mut g = BondGraph::new();
    let jm = g.add("jm", OneJunction).unwrap();
    let mass = g
        .add("mass", Inertia::multi(m, p0.to_vec()).unwrap())
        .unwrap();
    let law = boxed_law(|_, t| {
        set(t, (0, 0), 0.6);
        set(t, (1, 0), 0.8);
    });
    let mtf = g
        .add("mtf", MatrixTransformer::new(2, 1, vec![], law).unwrap())
        .unwrap();
    let z = g.add("z", ZeroJunction).unwrap();
    let c = g
        .add("spring", Capacitor::new(1.0 / k, q0).unwrap())
        .unwrap();
    g.connect((jm, None), (mass, Some(0))).unwrap();
    g.connect((jm, None), (mtf, Some(0))).unwrap();
    g.connect((mtf, Some(1)), (z, None)).unwrap();
    g.connect((z, None), (c, Some(0))).unwrap();
    assemble(g)
}

/// A boxed matrix-modulus law (the matrix type is inferred where it is used).
pub type BoxedLaw<T> = Box<dyn Fn(&Io<'_>, &mut T)>;

/// Box a matrix-modulus law without naming the matrix type.
pub fn boxed_law<T>(f: impl Fn(&Io<'_>, &mut T) + 'static) -> BoxedLaw<T> {
    Box::new(f)
}

/// `t[ij] = v` for a matrix whose type is not named here.
pub fn set<T: std::ops::IndexMut<(usize, usize), Output = f64>>(
    t: &mut T,
    ij: (usize, usize),
    v: f64,
) {
    t[ij] = v;
}

/// Settings for a run of `t_end` seconds.
pub fn settings(method: Method, t_end: f64, dt_out: f64, rtol: f64, atol: f64) -> Settings {
    Settings {
        t_start: 0.0,
        t_end,
        dt_out,
        method,
        rtol,
        atol,
        ..Settings::default()
    }
}
