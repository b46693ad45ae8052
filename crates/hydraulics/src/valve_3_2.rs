//! 3/2 valve `hydraulics.valve_3_2`: three ports `P`, `A`, `T`, two positions — `A` to tank
//! (P blocked) at u = 0, `P` to `A` (T blocked) at u = 1 — proportioned by u ∈ [0, 1]
//! (clamped); with `normally_open` the positions swap (P→A at u = 0).
//!
//! ```text
//! o = clamp(u, 0, 1)  (1 − clamp(u, 0, 1) when normally open)
//! Q_PA = α·o·regRoot(P_P − P_A)     + g_leak·(P_P − P_A)
//! Q_AT = α·(1 − o)·regRoot(P_A − P_T) + g_leak·(P_A − P_T)
//! ```
//!
//! Two metering edges of one spool, each an orifice (Merritt, *Hydraulic Control Systems*,
//! 1967), with a laminar leak across each. Flows into the valve: P: Q_PA, A: Q_AT − Q_PA,
//! T: −Q_AT (they sum to zero), and the power Q_PA·ΔP + Q_AT·ΔP ≥ 0 is dissipated. The
//! single-acting cylinder's valve: u = 1 extends, u = 0 lets the load retract it.
//!
//! Causality: conductance at all three ports.

use crate::orifice;
use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage,
};

use crate::orifice::{reg_root, reg_root_derivative};

/// A 3/2 valve.
///
/// * `alpha` — orifice coefficient α of each edge at full opening, m³/(s·√Pa), > 0.
/// * `u` — command, dimensionless, may be modulated; clamped to [0, 1].
/// * `normally_open` — whether u = 0 connects P to A.
/// * `g_leak` — leak conductance of each edge, m³/(s·Pa), ≥ 0; `p_tr` — regRoot transition
///   pressure, Pa, ≥ 0.
#[derive(Debug)]
pub struct Valve32 {
    alpha: f64,
    u: Param,
    normally_open: bool,
    g_leak: f64,
    p_tr: f64,
}

impl Valve32 {
    /// A 3/2 valve; see the struct documentation for the parameters.
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

    /// The P→A opening and its slope do/du at command `u`.
    fn opening(&self, u: f64) -> (f64, f64) {
        crate::valve_2_2::command_opening(u, self.normally_open)
    }

    /// The edge flows `(Q_PA, Q_AT)` at command `u` and pressures P, A, T.
    #[must_use]
    pub fn flows(&self, u: f64, p: &[f64; 3]) -> (f64, f64) {
        let o = self.opening(u).0;
        let (d_pa, d_at) = (p[0] - p[1], p[1] - p[2]);
        (
            self.alpha * o * reg_root(d_pa, self.p_tr) + self.g_leak * d_pa,
            self.alpha * (1.0 - o) * reg_root(d_at, self.p_tr) + self.g_leak * d_at,
        )
    }
}

impl Element for Valve32 {
    fn kind(&self) -> &str {
        "hydraulics.valve_3_2"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(["P", "A", "T"].map(|n| PortSpec::new(n, 1)).to_vec())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::FlowOut; 3]])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.u.signal_inputs()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let mut reads: Vec<Slot> = (0..3).map(Slot::Effort).collect();
        reads.extend((0..self.u.n_inputs()).map(Slot::Input));
        vec![Stage {
            writes: (0..3).map(Slot::Flow).collect(),
            reads,
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let p = [io.e(0, 0), io.e(1, 0), io.e(2, 0)];
        let (q_pa, q_at) = self.flows(self.u.value(io, 0), &p);
        io.set_f_in(0, 0, q_pa);
        io.set_f_in(1, 0, q_at - q_pa);
        io.set_f_in(2, 0, -q_at);
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let p = [io.e(0, 0), io.e(1, 0), io.e(2, 0)];
        let (o, d) = self.opening(self.u.value(io, 0));
        let (d_pa, d_at) = (p[0] - p[1], p[1] - p[2]);
        let (rr, drr) = (
            |x: f64| reg_root(x, self.p_tr),
            |x: f64| reg_root_derivative(x, self.p_tr),
        );
        // conductances of the two edges, and their flows' slopes in u
        let g_pa = self.alpha * o * drr(d_pa) + self.g_leak;
        let g_at = self.alpha * (1.0 - o) * drr(d_at) + self.g_leak;
        let (du_pa, du_at) = (self.alpha * d * rr(d_pa), -self.alpha * d * rr(d_at));
        // rows: f_P = Q_PA, f_A = Q_AT − Q_PA, f_T = −Q_AT; columns P, A, T
        let rows = [
            ([g_pa, -g_pa, 0.0], du_pa),
            ([-g_pa, g_pa + g_at, -g_at], du_at - du_pa),
            ([0.0, -g_at, g_at], -du_at),
        ];
        for (port, (cols, du)) in rows.iter().enumerate() {
            let row = jac.row(Slot::Flow(port), 0);
            for (k, v) in cols.iter().enumerate() {
                jac.set(row, jac.effort_col(k, 0), *v);
            }
            self.u
                .partials(io, 0, |i, dv| jac.set(row, jac.input_col(i, 0), du * dv));
        }
        true
    }
}

/// Kind `hydraulics.valve_3_2`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.valve_3_2",
    "3/2 valve, ports P, A, T: Q_PA = α·u·regRoot(·), Q_AT = α·(1 − u)·regRoot(·), u ∈ [0, 1]",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::modulated(
            "u",
            "1",
            "command, clamped to [0, 1]: 0 connects A to T, 1 P to A",
        ),
        ParamDecl::flag("normally_open", false, "whether u = 0 connects P to A"),
        ParamDecl::number("g_leak", "m³/(s·Pa)", "leak conductance of each edge")
            .non_negative()
            .default(0.0),
        orifice::P_TR,
    ],
    |p| {
        Ok(Box::new(Valve32::new(
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
#[allow(clippy::float_cmp)] // exact zeros and copied flows are meant exactly
mod tests {
    use super::*;

    #[test]
    fn switches_a_between_supply_and_tank() {
        let v = Valve32::new(1e-6, 0.0, false, 0.0, 0.0).unwrap();
        let p = [20e6, 11e6, 2e6];
        assert_eq!(v.flows(0.0, &p), (0.0, 1e-6 * 3e3));
        assert_eq!(v.flows(1.0, &p), (1e-6 * 3e3, 0.0));
        let (q_pa, q_at) = v.flows(0.25, &p);
        assert!((q_pa - 0.25e-6 * 3e3).abs() < 1e-18 && (q_at - 0.75e-6 * 3e3).abs() < 1e-18);
        let no = Valve32::new(1e-6, 0.0, true, 0.0, 0.0).unwrap();
        assert_eq!(no.flows(0.0, &p), v.flows(1.0, &p));
    }

    #[test]
    fn conserves_volume_and_dissipates() {
        let v = Valve32::new(1e-6, 0.0, false, 1e-13, 1e5).unwrap();
        for u in [-0.2, 0.0, 0.4, 1.0] {
            for p in [[20e6, 11e6, 0.0], [1e6, 11e6, 0.0], [5e6, 1e6, 3e6]] {
                let (q_pa, q_at) = v.flows(u, &p);
                let q = [q_pa, q_at - q_pa, -q_at];
                assert!(q.iter().sum::<f64>().abs() <= 1e-18);
                assert!(p[0] * q[0] + p[1] * q[1] + p[2] * q[2] >= 0.0, "{u} {p:?}");
            }
        }
    }

    #[test]
    fn partials_match_central_differences() {
        use bondgraph::check_partials;
        let u = Param::modulated(vec!["u".into()], |_, u| u[0]);
        let v = Valve32::new(1e-6, u, false, 1e-13, 1e5).unwrap();
        let ports = [(1, 1.0, PortCausality::FlowOut); 3];
        for u in [0.2, 0.6, 1.3] {
            let point = [20e6, 1e-4, 11e6, 1e-4, 1e5, 1e-4, u];
            assert_eq!(check_partials(&v, &ports, &point), Ok(1), "{u}");
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(Valve32::new(-1e-6, 0.0, false, 0.0, 1e5).is_err());
        assert!(Valve32::new(1e-6, f64::INFINITY, false, 0.0, 1e5).is_err());
    }
}
