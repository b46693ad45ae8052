//! A small hydraulic circuit built through the library API alone (no model file):
//!
//! ```text
//!  pump (Sf, 12 l/min) ─⇀ line (0) ─⇀ hose (chamber, 0.5 l)
//!                         line ─⇀ bleed (orifice) ─⇀ tank
//!                         line ─⇀ throttle (orifice) ─⇀ cyl.A
//!  cyl.B ─⇀ outlet (orifice) ─⇀ tank            cyl.mech ─⇀ load (1): mass, spring, damper
//! ```
//!
//! A fixed-displacement pump feeds a line that bleeds to tank through an orifice, and pushes
//! a cylinder against a spring through a throttle; the rod side drains through an outlet
//! orifice. When everything has come to rest, all the pump flow leaves through the bleed, so
//! `P_line = (Q/α_bleed)²` (for P ≫ p_tr), the rod side is at tank pressure, and the spring
//! holds `k·s = A_p·P_line`. The program prints the simulated and the analytic rest state.
//!
//! Run with `cargo run -p bg-hydraulics --example hydraulic_circuit`.

use bg_hydraulics::{reg_root, Chamber, Cylinder, EndStopSpec, InitialPressures, Orifice};
use bondgraph::{
    assign_causality, simulate, solve_steady, BondGraph, Capacitor, Condition, EffortSource,
    FlowSource, Inertia, OneJunction, Output, Resistor, Settings, StateEquations, SteadyRequest,
    ZeroJunction,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let beta = 1.4e9; // Pa
    let q_pump = 2e-4; // m³/s (12 l/min)
    let alpha_bleed = 5e-8; // m³/(s·√Pa)
    let p_tr = 1e5; // Pa
    let (a_p, a_r) = (2e-3, 1e-3); // m²
    let k = 5e5; // N/m

    let mut g = BondGraph::new();
    g.add("pump", FlowSource::new(q_pump))?;
    g.add("line", ZeroJunction)?;
    g.add("hose", Chamber::fixed(0.5e-3, beta, 0.0)?)?;
    g.add("bleed", Orifice::new(alpha_bleed, 1.0, p_tr)?)?;
    g.add("throttle", Orifice::new(1e-6, 1.0, p_tr)?)?;
    g.add("outlet", Orifice::new(2e-7, 1.0, p_tr)?)?;
    g.add("tank1", EffortSource::new(0.0))?;
    g.add("tank2", EffortSource::new(0.0))?;

    let mut cyl = Cylinder::new(a_p, a_r, 0.02, 0.52, 0.5, beta);
    cyl.initial = InitialPressures::Given { p_p: 0.0, p_r: 0.0 };
    cyl.end_stop = Some(EndStopSpec {
        k: 1e8,
        c: 1e5,
        width: 1e-4,
    });
    let cyl = cyl.add_to(&mut g, "cyl")?;

    g.add("load", OneJunction)?;
    g.add("mass", Inertia::new(50.0, 0.0)?)?;
    g.add("spring", Capacitor::new(1.0 / k, 0.0)?)?;
    g.add("damper", Resistor::new(5e3)?)?;

    for (from, to) in [
        ("pump", "line"),
        ("line", "hose"),
        ("line", "bleed"),  // bleed.a
        ("bleed", "tank1"), // bleed.b
        ("line", "throttle"),
        ("throttle", cyl.a.as_str()),
        (cyl.b.as_str(), "outlet"),
        ("outlet", "tank2"),
        (cyl.mech.as_str(), "load"),
        ("load", "mass"),
        ("load", "spring"),
        ("load", "damper"),
    ] {
        g.connect_names(from, to)?;
    }

    let mut eqs = StateEquations::new(assign_causality(g)?)?;
    let probe = |name: &str| {
        eqs.probe(name)
            .ok_or_else(|| format!("no variable `{name}`"))
    };
    let outputs = vec![
        Output {
            name: "s".into(),
            probe: probe("cyl_piston.s")?,
        },
        Output {
            name: "p_line".into(),
            probe: probe("hose.p")?,
        },
        Output {
            name: "p_p".into(),
            probe: probe("cyl_chamber_p.p")?,
        },
        Output {
            name: "p_r".into(),
            probe: probe("cyl_chamber_r.p")?,
        },
    ];
    let settings = Settings {
        t_end: 20.0,
        dt_out: 1.0,
        ..Settings::default()
    };
    let x0 = eqs.initial_state();
    // The same rest state as a solve (bondgraph::solve_steady): the line, chamber and spring
    // states such that no pressure changes and nothing moves, from the empty start.
    let index = |name: &str| {
        eqs.states()
            .iter()
            .position(|s| s.name == name)
            .ok_or_else(|| format!("no state `{name}`"))
    };
    let unknowns = [
        "hose.p",
        "cyl_chamber_p.p",
        "cyl_chamber_r.p",
        "spring.q",
        "mass.p",
    ]
    .iter()
    .map(|n| index(n))
    .collect::<Result<Vec<_>, _>>()?;
    let conditions = unknowns
        .iter()
        .map(|&state| Condition::Derivative { state, value: 0.0 })
        .collect();
    let mut guess = x0.clone();
    guess[unknowns[0]] = 1e6; // a pressure scale to start from
    let rest = solve_steady(
        &eqs,
        0.0,
        &guess,
        &SteadyRequest::new(unknowns.clone(), conditions),
    )?;
    let (p_solved, q_solved) = (rest.x[unknowns[0]], rest.x[unknowns[3]]);
    let run = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
    if let Some(e) = &run.error {
        return Err(format!("the run stopped: {e}").into());
    }

    println!("   t [s]    s [m]   P_line [MPa]   P_p [MPa]   P_r [MPa]");
    for row in &run.trajectory.rows {
        println!(
            "{:8.2} {:8.4} {:14.4} {:11.4} {:11.4}",
            row[0],
            row[1],
            row[2] / 1e6,
            row[3] / 1e6,
            row[4] / 1e6
        );
    }
    // Rest state: Q = α·regRoot(P) through the bleed, k·s = A_p·P − A_r·0.
    let mut p = (q_pump / alpha_bleed).powi(2);
    for _ in 0..50 {
        // Newton on α·regRoot(P) = Q (regRoot differs from √P by a few 1e-5 here)
        let f = alpha_bleed * reg_root(p, p_tr) - q_pump;
        let d = (alpha_bleed * (reg_root(p * (1.0 + 1e-7), p_tr) - reg_root(p, p_tr))) / (p * 1e-7);
        p -= f / d;
    }
    let s_rest = a_p * p / k;
    let last = run.trajectory.rows.last().ok_or("no rows")?;
    println!(
        "rest state: P_line {:.6} MPa (analytic {:.6}), s {:.6} m (analytic {:.6})",
        last[2] / 1e6,
        p / 1e6,
        last[1],
        s_rest
    );
    println!(
        "solved rest state (Newton, {} iterations): P_line {:.6} MPa, spring deflection {:.6} m",
        rest.iterations,
        p_solved / 1e6,
        q_solved
    );
    for w in &run.watched {
        println!(
            "minimum {} of {}: {:.4e} Pa{}",
            w.name,
            w.element,
            w.min,
            w.warning
                .as_deref()
                .map_or(String::new(), |m| format!(" ({m})"))
        );
    }
    println!("solver: {}", run.stats);
    if (last[1] - s_rest).abs() > 1e-4 * s_rest || (last[2] - p).abs() > 1e-4 * p {
        return Err("the rest state does not match the analytic one".into());
    }
    Ok(())
}
