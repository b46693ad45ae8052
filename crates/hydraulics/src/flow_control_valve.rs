//! Flow-control valve with pressure compensator `hydraulics.flow_control_valve`: a metering
//! orifice from `P` to `A` with a compensator in series that holds the drop across the
//! orifice at its spring's pressure Δp_c, so the flow is the set flow whatever the load.
//!
//! ```text
//! Q = q_set·regRoot(Δp_eff)/regRoot(Δp_c) + g_leak·Δp              Δp = P_P − P_A
//! Δp_eff = Δp_c·sat(Δp/Δp_c),  sat(ξ) = ξ below 1 − ε, 1 above 1 + ε, C¹ between
//! ```
//!
//! With the metering orifice α_m = q_set/√Δp_c: while Δp < Δp_c the compensator is wide open
//! and the valve is the orifice (Q = α_m·√Δp); above it the compensator throttles so that the
//! orifice sees Δp_c and Q = q_set (the two-way pressure-compensated flow control of Merritt,
//! *Hydraulic Control Systems*, 1967, and Manring, *Hydraulic Control Systems*, 2005; the
//! compensator's own drop when wide open and its dynamics are neglected). The knee is rounded
//! as the upper corner of [`crate::ramp`] (`sat(ξ) = ramp(ξ)` for ξ > 0, ξ itself below).
//! Reverse flow (Δp < 0) passes the metering orifice uncompensated. `q_set` may be a signal (a
//! proportional flow control); negative values are taken as 0.
//!
//! Causality: conductance at both ports. Dissipates Q·Δp ≥ 0.

use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage,
};

use crate::orifice::{reg_root, reg_root_derivative};
use crate::ramp::ramp;

/// A pressure-compensated flow-control valve.
///
/// * `q_set` — set flow, m³/s, may be modulated; negative values act as 0.
/// * `dp_comp` — compensator pressure Δp_c, Pa, > 0.
/// * `smoothing` — half-width ε of the rounded knee, fraction of Δp_c, in [0, 0.5].
/// * `g_leak` — leak conductance, m³/(s·Pa), ≥ 0; `p_tr` — regRoot transition pressure, Pa.
#[derive(Debug)]
pub struct FlowControlValve {
    q_set: Param,
    dp_comp: f64,
    eps: f64,
    g_leak: f64,
    p_tr: f64,
    rr_comp: f64,
}

impl FlowControlValve {
    /// A flow-control valve; see the struct documentation for the parameters.
    pub fn new(
        q_set: impl Into<Param>,
        dp_comp: f64,
        smoothing: f64,
        g_leak: f64,
        p_tr: f64,
    ) -> Result<Self, ParamError> {
        ParamError::positive("dp_comp", dp_comp)?;
        ParamError::non_negative("g_leak", g_leak)?;
        ParamError::non_negative("p_tr", p_tr)?;
        if !(0.0..=0.5).contains(&smoothing) {
            return Err(ParamError::OutOfRange {
                param: "smoothing".into(),
                value: smoothing,
                requirement: "between 0 and 0.5",
            });
        }
        let q_set = q_set.into();
        if let Some(q) = q_set.constant() {
            ParamError::finite("q_set", q)?;
        }
        Ok(Self {
            q_set,
            dp_comp,
            eps: smoothing,
            g_leak,
            p_tr,
            rr_comp: reg_root(dp_comp, p_tr),
        })
    }

    /// The metered drop Δp_eff and its slope dΔp_eff/dΔp.
    fn metered(&self, dp: f64) -> (f64, f64) {
        let xi = dp / self.dp_comp;
        if xi <= 0.5 {
            (dp, 1.0)
        } else {
            let (s, ds) = ramp(xi, self.eps);
            (self.dp_comp * s, ds)
        }
    }

    /// Flow from P to A at set flow `q_set` and pressures `p_p`, `p_a`.
    #[must_use]
    pub fn flow(&self, q_set: f64, p_p: f64, p_a: f64) -> f64 {
        let dp = p_p - p_a;
        let m = self.metered(dp).0;
        q_set.max(0.0) * reg_root(m, self.p_tr) / self.rr_comp + self.g_leak * dp
    }
}

impl Element for FlowControlValve {
    fn kind(&self) -> &str {
        "hydraulics.flow_control_valve"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("P", 1), PortSpec::new("A", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::FlowOut; 2]])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.q_set.signal_inputs()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let mut reads = vec![Slot::Effort(0), Slot::Effort(1)];
        reads.extend((0..self.q_set.n_inputs()).map(Slot::Input));
        vec![Stage {
            writes: vec![Slot::Flow(0), Slot::Flow(1)],
            reads,
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let q = self.flow(self.q_set.value(io, 0), io.e(0, 0), io.e(1, 0));
        io.set_f_in(0, 0, q);
        io.set_f_in(1, 0, -q);
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let q_set = self.q_set.value(io, 0);
        let dp = io.e(0, 0) - io.e(1, 0);
        let (m, dm) = self.metered(dp);
        let q = q_set.max(0.0);
        let dq_dp = q * reg_root_derivative(m, self.p_tr) * dm / self.rr_comp + self.g_leak;
        let dq_dset = if q_set > 0.0 {
            reg_root(m, self.p_tr) / self.rr_comp
        } else {
            0.0
        };
        for (port, s) in [(0, 1.0), (1, -1.0)] {
            let row = jac.row(Slot::Flow(port), 0);
            jac.set(row, jac.effort_col(0, 0), s * dq_dp);
            jac.set(row, jac.effort_col(1, 0), -s * dq_dp);
            self.q_set.partials(io, 0, |i, d| {
                jac.set(row, jac.input_col(i, 0), s * dq_dset * d);
            });
        }
        true
    }
}

/// Kind `hydraulics.flow_control_valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.flow_control_valve",
    "pressure-compensated flow control P → A: Q = q_set once Δp ≥ dp_comp, the metering orifice below",
    &[
        ParamDecl::modulated("q_set", "m³/s", "set flow (negative acts as 0)"),
        ParamDecl::number("dp_comp", "Pa", "compensator pressure Δp_c").positive(),
        ParamDecl::number("smoothing", "1", "half-width ε of the rounded knee, fraction of dp_comp")
            .range(bondgraph::kind::Range::closed(0.0, 0.5))
            .default(0.05),
        ParamDecl::number("g_leak", "m³/(s·Pa)", "leak conductance").non_negative().default(0.0),
        crate::orifice::P_TR,
    ],
    |p| {
        Ok(Box::new(FlowControlValve::new(
            p.modulated("q_set")?,
            p.number("dp_comp")?,
            p.number("smoothing")?,
            p.number("g_leak")?,
            p.number("p_tr")?,
        )?))
    },
)
.example("q_set = 3e-4, dp_comp = 6e5");

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact zeros and copied flows are meant exactly
mod tests {
    use super::*;

    #[test]
    fn holds_the_set_flow_above_the_compensator_pressure() {
        let v = FlowControlValve::new(1e-3, 1e6, 0.05, 0.0, 1e5).unwrap();
        for dp in [1.06e6, 3e6, 25e6] {
            assert!((v.flow(1e-3, dp + 1e6, 1e6) - 1e-3).abs() < 1e-15, "{dp}");
        }
        // below it, the metering orifice α_m = q_set/regRoot(Δp_c)
        for dp in [1e4, 2e5, 0.9e6] {
            let e = 1e-3 * reg_root(dp, 1e5) / reg_root(1e6, 1e5);
            assert!((v.flow(1e-3, dp, 0.0) - e).abs() < 1e-15, "{dp}");
        }
        // reverse: the orifice backwards, uncompensated
        let e = -1e-3 * reg_root(4e6, 1e5) / reg_root(1e6, 1e5);
        assert!((v.flow(1e-3, 0.0, 4e6) - e).abs() < 1e-15);
        assert_eq!(v.flow(-1.0, 5e6, 0.0), 0.0);
    }

    #[test]
    fn partials_match_central_differences() {
        use bondgraph::check_partials;
        let q = Param::modulated(vec!["q".into()], |_, u| u[0]);
        let v = FlowControlValve::new(q, 1e6, 0.05, 1e-13, 1e5).unwrap();
        let ports = [(1, 1.0, PortCausality::FlowOut); 2];
        for (pp, pa) in [(5e6, 1e6), (1.6e6, 1e6), (1.98e6, 1e6), (1e6, 3e6)] {
            let point = [pp, 1e-4, pa, -1e-4, 1e-3];
            assert_eq!(check_partials(&v, &ports, &point), Ok(1), "{pp} {pa}");
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(FlowControlValve::new(1e-3, 0.0, 0.05, 0.0, 1e5).is_err());
        assert!(FlowControlValve::new(1e-3, 1e6, 0.6, 0.0, 1e5).is_err());
        assert!(FlowControlValve::new(f64::NAN, 1e6, 0.05, 0.0, 1e5).is_err());
    }
}
