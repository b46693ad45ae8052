//! Volume and power of the hydraulic storage kinds at random states and port flows: the
//! line, the accumulator, the tank and a chamber with entrained air and cavitation.
//!
//! * power: the power into the line is dE/dt + Σ R·q² (dissipation ≥ 0); into the
//!   accumulator, dE/dt (E its stored energy, differentiated along ẋ);
//! * volume: the oil in the line changes at Σ C·ṗ_i = f_in,a + f_in,b; the accumulator's and
//!   the tank's volume at f_in; the chamber's liquid at (V/β_eff(p) + C_cav(p))·ṗ = f_in.
//!
//! Each to 1e-9 of the terms' scale (1e-6 for the accumulator's energy, a difference
//! quotient).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::float_cmp)] // copied values compare exactly

use bg_hydraulics::{Accumulator, Chamber, FluidOptions, Leakage, Line, LineSpec, Tank, Wall};
use bondgraph::*;
use proptest::prelude::*;

struct Circuit {
    eqs: StateEquations,
    line: (usize, f64, f64, f64),
    chamber_fluid: bg_hydraulics::Fluid,
}

/// pump → line → j (0) → accumulator;  j → leak → tank;  pump2 → chamber.
fn circuit(n: usize, q1: f64, q2: f64) -> Circuit {
    let spec = LineSpec {
        segments: n,
        wall: Wall::Hose { expansion: 1e-9 },
        ..LineSpec::new(3.0, 0.012, 1.6e9)
    };
    let line = Line::new(&spec, 0.0).unwrap();
    let (c, r, i) = line.segment();
    let chamber = Chamber::fixed(2e-3, 1.5e9, 0.0)
        .unwrap()
        .with_fluid(FluidOptions {
            air: Some((0.01, 1.3)),
            cavitation: Some((2e3, 1e3)),
            ..FluidOptions::default()
        })
        .unwrap();
    let chamber_fluid = *chamber.fluid().unwrap();
    let mut g = BondGraph::new();
    g.add("pump", FlowSource::new(q1)).unwrap();
    g.add("line", line).unwrap();
    g.add("j", ZeroJunction).unwrap();
    g.add("acc", Accumulator::new(3e6, 1e-3, 1.4).unwrap())
        .unwrap();
    g.add("leak", Leakage::internal(1e10).unwrap()).unwrap();
    g.add("tank", Tank::new(1e5, 0.0).unwrap()).unwrap();
    g.add("pump2", FlowSource::new(q2)).unwrap();
    g.add("oil", chamber).unwrap();
    for (a, b) in [
        ("pump", "line"),
        ("line", "j"),
        ("j", "acc"),
        ("j", "leak"),
        ("leak", "tank"),
        ("pump2", "oil"),
    ] {
        g.connect_names(a, b).unwrap();
    }
    let eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
    Circuit {
        eqs,
        line: (n, c, r, i),
        chamber_fluid,
    }
}

fn state(eqs: &StateEquations, name: &str) -> usize {
    eqs.states().iter().position(|s| s.name == name).unwrap()
}

fn read(eqs: &StateEquations, name: &str, t: f64, x: &[f64]) -> f64 {
    eqs.read(eqs.probe(name).unwrap(), t, x)
}

fn element(eqs: &StateEquations, name: &str) -> usize {
    eqs.graph().find(name).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn storage_kinds_keep_volume_and_power(
        n in 1usize..6,
        u in proptest::collection::vec(-1.0f64..1.0, 16),
        q1 in -1e-3f64..1e-3,
        q2 in -1e-3f64..1e-3,
    ) {
        let Circuit { eqs, line: (n, c, r, i), chamber_fluid } = circuit(n, q1, q2);
        let mut x = eqs.initial_state();
        // line pressures in [−0.1, 20] MPa, flows ±1 l/s
        for k in 1..=n {
            x[state(&eqs, &format!("line.p[{k}]"))] = 1e7 * (1.0 + u[k]) - 1e5;
            x[state(&eqs, &format!("line.q[{k}]"))] = 1e-3 * u[k + 6];
        }
        // the accumulator from slightly empty to nearly full; the chamber from the
        // cavitation band (p_abs − p_v ≥ 1 kPa) to 30 MPa
        let ia = state(&eqs, "acc.V");
        x[ia] = 1e-3 * (0.45 + 0.5 * u[12]) - 5e-6;
        let ic = state(&eqs, "oil.p");
        let p_floor = 2e3 - 101_325.0 + 1e3;
        x[ic] = p_floor + (3e7 - p_floor) * (0.5 + 0.5 * u[13]).powi(3);
        x[state(&eqs, "tank.V")] = u[14];
        let t = 0.0;
        eqs.evaluate(t, &x);
        let mut dx = vec![0.0; x.len()];
        eqs.rhs(t, &x, &mut dx);

        // line: power and volume
        let id = element(&eqs, "line");
        let p_in = eqs.power_into(id);
        let mut de = 0.0;
        let mut diss = 0.0;
        let mut dvol = 0.0;
        let mut scale: f64 = eqs.power_scale(id);
        for k in 1..=n {
            let (ip, iq) = (state(&eqs, &format!("line.p[{k}]")), state(&eqs, &format!("line.q[{k}]")));
            de += c * x[ip] * dx[ip] + i * x[iq] * dx[iq];
            diss += r * x[iq] * x[iq];
            dvol += c * dx[ip];
            scale = scale.max((c * x[ip] * dx[ip]).abs()).max((i * x[iq] * dx[iq]).abs());
        }
        prop_assert!(diss >= 0.0);
        prop_assert!((p_in - de - diss).abs() <= 1e-9 * scale, "line power: in {p_in:e}, dE/dt {de:e}, R q² {diss:e}");
        // f_in,a = flow of pump → line; f_in,b = −flow of line → j
        let f_a = read(&eqs, "line.a.f", t, &x);
        let f_b = -read(&eqs, "line.b.f", t, &x);
        prop_assert!((dvol - (f_a + f_b)).abs() <= 1e-9 * (f_a.abs() + f_b.abs() + dvol.abs()), "line volume: {dvol:e} vs {:e}", f_a + f_b);

        // accumulator: power = dE/dt along ẋ (central difference of its stored energy)
        let id = element(&eqs, "acc");
        let acc = eqs.graph().node(id).element.as_ref();
        let p_acc = eqs.power_into(id);
        let v = x[ia];
        let h = 1e-7 * 1e-3 / dx[ia].abs().max(1e-12);
        let e = |v: f64| acc.stored_energy(&[v]).unwrap();
        let de_acc = (e(v + h * dx[ia]) - e(v - h * dx[ia])) / (2.0 * h);
        prop_assert!((p_acc - de_acc).abs() <= 1e-6 * p_acc.abs().max(1e-9), "accumulator: {p_acc:e} vs {de_acc:e}");
        let f_acc = read(&eqs, "acc.f", t, &x);
        prop_assert!((dx[ia] - f_acc).abs() <= 1e-15, "accumulator volume");

        // tank: dV/dt is the flow in (bond leak → tank points at it)
        let f_tank = read(&eqs, "tank.f", t, &x);
        prop_assert_eq!(dx[state(&eqs, "tank.V")], f_tank);

        // chamber: (V/β_eff + C_cav)·ṗ = f_in
        let p = x[ic];
        let f_in = read(&eqs, "oil.f", t, &x);
        let (k, _) = chamber_fluid.compressibility(p);
        let (_, dcav) = chamber_fluid.cavity(p);
        let stored = (2e-3 * k - dcav) * dx[ic];
        prop_assert!((stored - f_in).abs() <= 1e-9 * f_in.abs().max(1e-15), "chamber volume: {stored:e} vs {f_in:e} at {p:e} Pa");
        prop_assert_eq!(f_in, q2);
    }
}
