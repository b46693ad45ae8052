//! Pressure relief valve `hydraulics.relief_valve`: a spring-loaded poppet between `P` and `T`
//! that opens when the pressure drop across it exceeds the cracking pressure.
//!
//! ```text
//! x = ramp((Δp − p_crack)/Δp_override)        Δp = P_P − P_T
//! Q = α·x·regRoot(Δp) + g_leak·Δp              from P to T
//! ```
//!
//! The poppet's force balance puts its lift, and with it the opening area, in proportion to
//! the pressure above cracking (the *pressure override*): closed below `p_crack`, fully open
//! at `p_crack + Δp_override`. The oil passes the opening as through an orifice, so the flow
//! is the orifice law with that opening — the static characteristic of a direct-acting relief
//! valve in Merritt, *Hydraulic Control Systems* (1967), and Manring, *Hydraulic Control
//! Systems* (2005). This law was chosen over a linear gain Q = K·(Δp − p_crack) because its
//! parameters are the orifice's (α = C_d·w·√(2/ρ) at full opening, the same as for
//! `hydraulics.orifice`), it needs no separate rated flow, and the linear gain is only its
//! tangent at one operating point. With α and Δp_override the rated flow is
//! `Q_max = α·√(p_crack + Δp_override)`.
//!
//! The opening's corners are rounded over ±ε·Δp_override (`smoothing` = ε; see
//! [`crate::ramp`]), so the Jacobian is continuous when the valve cracks; the valve then
//! passes a trace of flow from Δp = p_crack − ε·Δp_override on.
//!
//! **Poppet dynamics** (optional): with `tau` the opening is a state that lags its static
//! value, `τ·dx/dt = ramp(…) − x` (a first-order poppet, starting closed). Without it the
//! opening follows the pressure instantly.
//!
//! Causality: conductance, both ports receive their pressure and set their flow (attach them
//! to 0-junctions with a chamber, or to pressure sources). Dissipates Q·Δp ≥ 0. Publishes the
//! opening `x`.

use crate::orifice;
use bondgraph::kind::{BuildError, Change, KindDecl, ParamDecl, Params, Simplification};
use bondgraph::ParamError;

use crate::pressure_valve::{Opening, PressureValve, G_LEAK, NO_SEAT_LEAK, SMOOTHING};

/// Parameters of a relief valve; [`ReliefValve::build`] makes the element.
#[derive(Clone, Debug, PartialEq)]
pub struct ReliefValve {
    /// Orifice coefficient α at full opening, m³/(s·√Pa), > 0 (`alpha`, or `cd`, `w`, `rho`).
    pub alpha: f64,
    /// Cracking pressure p_crack, Pa, > 0 (`p_crack`).
    pub p_crack: f64,
    /// Pressure override Δp_override from cracking to fully open, Pa, > 0 (`dp_override`,
    /// default 0.1·p_crack).
    pub dp_override: f64,
    /// Half-width ε of the rounded corners, fraction of `dp_override`, in [0, 0.5]
    /// (`smoothing`, default 0.05).
    pub smoothing: f64,
    /// Leak conductance of the closed seat, m³/(s·Pa), ≥ 0 (`g_leak`, default 1e-15).
    pub g_leak: f64,
    /// regRoot transition pressure, Pa, ≥ 0 (`p_tr`, default 1e5).
    pub p_tr: f64,
    /// Poppet time constant τ, s, > 0 (`tau`); `None` (default): no dynamics.
    pub tau: Option<f64>,
}

impl ReliefValve {
    /// A relief valve with coefficient `alpha` cracking at `p_crack`, the rest at defaults.
    #[must_use]
    pub fn new(alpha: f64, p_crack: f64) -> Self {
        Self {
            alpha,
            p_crack,
            dp_override: 0.1 * p_crack,
            smoothing: 0.05,
            g_leak: 1e-15,
            p_tr: 1e5,
            tau: None,
        }
    }

    /// The element (kind `hydraulics.relief_valve`, ports `P`, `T`).
    pub fn build(&self) -> Result<PressureValve, ParamError> {
        ParamError::positive("alpha", self.alpha)?;
        ParamError::positive("p_crack", self.p_crack)?;
        ParamError::positive("dp_override", self.dp_override)?;
        let opening = Opening {
            name: "x",
            alpha: self.alpha,
            c: [1.0, -1.0, 0.0],
            p_set: self.p_crack,
            band: self.dp_override,
            eps: self.smoothing,
        };
        PressureValve::new(
            "hydraulics.relief_valve",
            &["P", "T"],
            vec![opening],
            self.g_leak,
            self.p_tr,
            self.tau,
        )
    }
}

/// Kind `hydraulics.relief_valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.relief_valve",
    "relief valve P → T: x = ramp((Δp − p_crack)/dp_override), Q = α·x·regRoot(Δp) + g_leak·Δp; optional poppet lag tau",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::number("p_crack", "Pa", "cracking pressure").positive(),
        ParamDecl::number("dp_override", "Pa", "pressure rise from cracking to fully open").positive().optional("0.1·p_crack"),
        SMOOTHING,
        G_LEAK,
        orifice::P_TR,
        ParamDecl::number("tau", "s", "poppet time constant").positive().optional("no dynamics"),
    ],
    build,
)
.simplifications(&[
    NO_SEAT_LEAK,
    Simplification::new("static_poppet", "no poppet lag: x at its static opening", &[Change::Unset("tau")]),
])
.example("alpha = 2e-7, p_crack = 1.6e7");

fn build(p: &dyn Params) -> Result<Box<dyn bondgraph::Element>, BuildError> {
    let mut v = ReliefValve::new(orifice::alpha_of(p)?, p.number("p_crack")?);
    if let Some(d) = p.optional("dp_override")? {
        v.dp_override = d;
    }
    v.smoothing = p.number("smoothing")?;
    v.g_leak = p.number("g_leak")?;
    v.p_tr = p.number("p_tr")?;
    v.tau = p.optional("tau")?;
    Ok(Box::new(v.build()?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{reg_root, Chamber};
    use bondgraph::*;

    #[test]
    fn static_characteristic_is_the_closed_form() {
        let (a, pc, dpo) = (2e-7, 20e6, 2e6);
        let mut r = ReliefValve::new(a, pc);
        r.dp_override = dpo;
        let v = r.build().unwrap();
        let q = |p: f64| v.flow(&[p, 0.0, 0.0]);
        // closed: the leak only
        for p in [0.0, 1e6, 19.8e6] {
            assert!((q(p) - 1e-15 * p).abs() <= 1e-12 * q(p).abs(), "{p}");
        }
        // on the linear part of the override: α·(Δp − p_crack)/Δp_override·regRoot(Δp)
        for p in [20.5e6, 21e6, 21.8e6] {
            let e = a * (p - pc) / dpo * reg_root(p, 1e5) + 1e-15 * p;
            assert!((q(p) - e).abs() <= 1e-12 * e, "{p}: {} {e}", q(p));
        }
        // fully open: the orifice
        let e = a * reg_root(25e6, 1e5) + 1e-15 * 25e6;
        assert!((q(25e6) - e).abs() <= 1e-12 * e);
        // reverse drop: the seat leaks backwards only
        assert!((q(-5e6) + 5e-9).abs() < 1e-20);
        assert_eq!(v.kind(), "hydraulics.relief_valve");
    }

    /// A constant flow into a chamber relieved to tank: the pressure settles where the valve
    /// passes the flow, Q_in = α·(p − p_crack)/Δp_override·regRoot(p) + g_leak·p, solved here
    /// by bisection; with and without poppet dynamics.
    #[test]
    fn relieves_a_pumped_chamber_at_the_closed_form_pressure() {
        let (a, pc, dpo, q_in) = (2e-7, 20e6, 2e6, 4e-4);
        let g = |p: f64| a * (p - pc) / dpo * reg_root(p, 1e5) + 1e-15 * p - q_in;
        let (mut lo, mut hi) = (pc + 0.1 * dpo, pc + 0.9 * dpo); // the linear part
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if g(mid) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let p_ss = 0.5 * (lo + hi);
        for tau in [None, Some(5e-3)] {
            let mut r = ReliefValve::new(a, pc);
            r.dp_override = dpo;
            r.tau = tau;
            let mut gr = BondGraph::new();
            gr.add("pump", FlowSource::new(q_in)).unwrap();
            gr.add("line", ZeroJunction).unwrap();
            gr.add("hose", Chamber::fixed(1e-3, 1.5e9, 0.0).unwrap())
                .unwrap();
            gr.add("relief", r.build().unwrap()).unwrap();
            gr.add("tank", EffortSource::new(0.0)).unwrap();
            for (f, t) in [
                ("pump", "line"),
                ("line", "hose"),
                ("line", "relief"),
                ("relief", "tank"),
            ] {
                gr.connect_names(f, t).unwrap();
            }
            let mut eqs = StateEquations::new(assign_causality(gr).unwrap()).unwrap();
            let x0 = eqs.initial_state();
            let settings = Settings {
                t_end: 2.0,
                rtol: 1e-9,
                atol: 1e-9,
                ..Settings::default()
            };
            let run = simulate(&mut eqs, &x0, &settings, &[], vec![]);
            assert!(run.error.is_none(), "{:?}", run.error);
            let p = run.x_final[0];
            assert!((p - p_ss).abs() <= 1e-6 * p_ss, "{tau:?}: {p} vs {p_ss}");
        }
    }

    /// Held at a constant drop, the poppet opens as x(t) = x_ss·(1 − e^(−t/τ)).
    #[test]
    fn poppet_lag_is_first_order() {
        let (pc, dpo, tau) = (20e6, 2e6, 0.01);
        let mut r = ReliefValve::new(2e-7, pc);
        r.dp_override = dpo;
        r.tau = Some(tau);
        let mut g = BondGraph::new();
        g.add("supply", EffortSource::new(pc + 0.4 * dpo)).unwrap();
        g.add("relief", r.build().unwrap()).unwrap();
        g.add("tank", EffortSource::new(0.0)).unwrap();
        g.connect_names("supply", "relief").unwrap();
        g.connect_names("relief", "tank").unwrap();
        let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        let x0 = eqs.initial_state();
        assert_eq!(x0, [0.0], "starts closed");
        for t_end in [0.5 * tau, tau, 3.0 * tau] {
            let settings = Settings {
                t_end,
                dt_out: t_end,
                rtol: 1e-10,
                atol: 1e-12,
                ..Settings::default()
            };
            let run = simulate(&mut eqs, &x0, &settings, &[], vec![]);
            let e = 0.4 * (1.0 - (-t_end / tau).exp());
            assert!(
                (run.x_final[0] - e).abs() <= 1e-8,
                "{t_end}: {:?}",
                run.x_final
            );
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(ReliefValve::new(0.0, 20e6).build().is_err());
        assert!(ReliefValve::new(1e-7, -1.0).build().is_err());
        let mut r = ReliefValve::new(1e-7, 20e6);
        r.dp_override = 0.0;
        assert!(r.build().is_err());
        r.dp_override = 1e6;
        r.smoothing = 0.7;
        assert!(r.build().is_err());
        r.smoothing = 0.0;
        r.tau = Some(-1.0);
        assert!(r.build().is_err());
    }
}
