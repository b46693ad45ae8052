//! 2/2 valve `hydraulics.valve_2_2`: two ports `P`, `A`, two positions (shut, open),
//! switched or proportioned by a signal u ∈ [0, 1] (clamped).
//!
//! ```text
//! o = clamp(u, 0, 1)            normally closed (u = 0: shut)
//! o = 1 − clamp(u, 0, 1)        normally open   (u = 0: open)
//! Q = α·o·regRoot(P_P − P_A) + g_leak·(P_P − P_A)        from P to A
//! ```
//!
//! An orifice whose opening is the commanded one (Merritt, *Hydraulic Control Systems*,
//! 1967), plus the laminar leak of the shut valve. Switching is as fast as u: give u as a
//! ramp in time (`"ramp(t - 1, 0.05)"`-like expressions) or through the core's `lag` for a
//! finite switching time. Both directions pass oil.
//!
//! Causality: conductance at both ports. Dissipates Q·(P_P − P_A) ≥ 0.

use crate::orifice;
use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage,
};

use crate::orifice::{reg_root, reg_root_derivative};

/// A 2/2 valve.
///
/// * `alpha` — orifice coefficient α at full opening, m³/(s·√Pa), > 0.
/// * `u` — command, dimensionless, may be modulated; clamped to [0, 1].
/// * `normally_open` — whether u = 0 is the open position.
/// * `g_leak` — leak conductance, m³/(s·Pa), ≥ 0; `p_tr` — regRoot transition pressure, Pa.
#[derive(Debug)]
pub struct Valve22 {
    alpha: f64,
    u: Param,
    normally_open: bool,
    g_leak: f64,
    p_tr: f64,
}

/// The opening of a switching valve's edge and its slope do/du at command `u`: `u` clamped
/// to [0, 1], or `1 − u` for a normally-open edge (shared by the 2/2 and 3/2 valves).
#[must_use]
pub(crate) fn command_opening(u: f64, normally_open: bool) -> (f64, f64) {
    let (o, d) = if u < 0.0 {
        (0.0, 0.0)
    } else if u > 1.0 {
        (1.0, 0.0)
    } else {
        (u, 1.0)
    };
    if normally_open {
        (1.0 - o, -d)
    } else {
        (o, d)
    }
}

impl Valve22 {
    /// A 2/2 valve; see the struct documentation for the parameters.
    pub fn new(
        alpha: f64,
        u: impl Into<Param>,
        normally_open: bool,
        g_leak: f64,
        p_tr: f64,
    ) -> Result<Self, ParamError> {
        ParamError::positive("alpha", alpha)?;
        ParamError::non_negative("g_leak", g_leak)?;
        ParamError::non_negative("p_tr", p_tr)?;
        let u = u.into();
        if let Some(v) = u.constant() {
            ParamError::finite("u", v)?;
        }
        Ok(Self {
            alpha,
            u,
            normally_open,
            g_leak,
            p_tr,
        })
    }

    /// The opening and its slope do/du at command `u` ([`command_opening`]).
    fn opening(&self, u: f64) -> (f64, f64) {
        command_opening(u, self.normally_open)
    }

    /// Flow from P to A at command `u` and pressures `p_p`, `p_a`.
    #[must_use]
    pub fn flow(&self, u: f64, p_p: f64, p_a: f64) -> f64 {
        let dp = p_p - p_a;
        self.alpha * self.opening(u).0 * reg_root(dp, self.p_tr) + self.g_leak * dp
    }
}

impl Element for Valve22 {
    fn kind(&self) -> &str {
        "hydraulics.valve_2_2"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("P", 1), PortSpec::new("A", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::FlowOut; 2]])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.u.signal_inputs()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let mut reads = vec![Slot::Effort(0), Slot::Effort(1)];
        reads.extend((0..self.u.n_inputs()).map(Slot::Input));
        vec![Stage {
            writes: vec![Slot::Flow(0), Slot::Flow(1)],
            reads,
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let q = self.flow(self.u.value(io, 0), io.e(0, 0), io.e(1, 0));
        io.set_f_in(0, 0, q);
        io.set_f_in(1, 0, -q);
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let dp = io.e(0, 0) - io.e(1, 0);
        let (o, d) = self.opening(self.u.value(io, 0));
        let dq_dp = self.alpha * o * reg_root_derivative(dp, self.p_tr) + self.g_leak;
        let dq_du = self.alpha * d * reg_root(dp, self.p_tr);
        for (port, s) in [(0, 1.0), (1, -1.0)] {
            let row = jac.row(Slot::Flow(port), 0);
            jac.set(row, jac.effort_col(0, 0), s * dq_dp);
            jac.set(row, jac.effort_col(1, 0), -s * dq_dp);
            self.u.partials(io, 0, |i, du| {
                jac.set(row, jac.input_col(i, 0), s * dq_du * du)
            });
        }
        true
    }
}

/// Kind `hydraulics.valve_2_2`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.valve_2_2",
    "2/2 valve P → A: Q = α·u·regRoot(Δp) + g_leak·Δp, u ∈ [0, 1] (1 − u normally open)",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::modulated("u", "1", "command, clamped to [0, 1]"),
        ParamDecl::flag("normally_open", false, "whether u = 0 is the open position"),
        ParamDecl::number("g_leak", "m³/(s·Pa)", "leak conductance")
            .non_negative()
            .default(0.0),
        orifice::P_TR,
    ],
    |p| {
        Ok(Box::new(Valve22::new(
            orifice::alpha_of(p)?,
            p.modulated("u")?,
            p.flag("normally_open")?,
            p.number("g_leak")?,
            p.number("p_tr")?,
        )?))
    },
)
.example("alpha = 1e-6, u = \"step(t - 1)\"");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opens_with_the_command_and_normally_open_inverts_it() {
        let nc = Valve22::new(1e-6, 0.0, false, 1e-13, 0.0).unwrap();
        let no = Valve22::new(1e-6, 0.0, true, 1e-13, 0.0).unwrap();
        for u in [-0.5, 0.0, 0.3, 1.0, 2.0] {
            let o = f64::clamp(u, 0.0, 1.0);
            let e = |o: f64| 1e-6 * o * 3e3 + 1e-13 * 9e6;
            assert!(
                (nc.flow(u, 10e6, 1e6) - e(o)).abs() <= 1e-15 * e(o).max(1.0),
                "{u}"
            );
            assert!((no.flow(u, 10e6, 1e6) - e(1.0 - o)).abs() <= 1e-15, "{u}");
        }
        // shut: the leak only, both ways
        assert!((nc.flow(0.0, 1e6, 10e6) + 9e-7).abs() < 1e-20);
    }

    #[test]
    fn partials_match_central_differences() {
        use bondgraph::check_partials;
        for normally_open in [false, true] {
            let u = Param::modulated(vec!["u".into()], |_, u| u[0]);
            let v = Valve22::new(1e-6, u, normally_open, 1e-13, 1e5).unwrap();
            let ports = [(1, 1.0, PortCausality::FlowOut); 2];
            for (pp, pa, u) in [(10e6, 1e6, 0.4), (1e6, 1.05e6, 0.7), (3e6, 2e6, 1.4)] {
                let point = [pp, 1e-4, pa, -1e-4, u];
                assert_eq!(check_partials(&v, &ports, &point), Ok(1), "{pp} {pa} {u}");
            }
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(Valve22::new(0.0, 0.0, false, 0.0, 1e5).is_err());
        assert!(Valve22::new(1e-6, f64::NAN, false, 0.0, 1e5).is_err());
        assert!(Valve22::new(1e-6, 0.0, false, -1.0, 1e5).is_err());
        assert!(Valve22::new(1e-6, 0.0, false, 0.0, -1.0).is_err());
    }
}
