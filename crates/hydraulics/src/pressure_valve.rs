//! The pressure-operated valve: what the relief, check, pilot-operated check, sequence,
//! pressure-reducing and counterbalance valves have in common (each kind is its own file and
//! builds one of these; see there for the law and its source).
//!
//! A poppet or spool held by a spring opens as the pressures acting on it overcome the spring:
//! each *opening* i has a drive
//!
//! ```text
//! ξᵢ = (Σₖ cᵢₖ·Pₖ − p_setᵢ)/Δpᵢ          (k over the ports; cᵢₖ the areas over the seat area)
//! xᵢ = ramp(ξᵢ)                           (crate::ramp: the clamp to [0, 1], corners rounded)
//! ```
//!
//! and the openings pass oil between the two main ports `0 → 1` as orifices in parallel, with
//! a laminar leak across the closed seat:
//!
//! ```text
//! Q = (Σᵢ αᵢ·xᵢ)·regRoot(P₀ − P₁) + g_leak·(P₀ − P₁)      (from port 0 to port 1)
//! ```
//!
//! A third port, the pilot, only senses its pressure: its flow is zero (the pilot piston's
//! displacement is neglected). Every opening is ≥ 0 and `regRoot` has the sign of its
//! argument, so `Q·(P₀ − P₁) ≥ 0`: the valve only dissipates, and the flow into port 0
//! leaves at port 1 (volume conserved exactly).
//!
//! **Dynamics** (optional, time constant τ): each opening becomes a state that follows its
//! static value, `τ·dxᵢ/dt = ramp(ξᵢ) − xᵢ` (a first-order spool or poppet; the openings then
//! stay in [0, 1] when they start there).
//!
//! Causality: every port receives its pressure and sets its flow (conductance), like the
//! [`Orifice`](crate::Orifice). Publishes each opening xᵢ (`x`, and for two openings the second
//! one's name, e.g. `x_check`).

use bondgraph::kind::{Change, ParamDecl, Range, Simplification};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, SignalSpec,
    Slot, Stage, StateSpec,
};

use crate::orifice::{reg_root, reg_root_derivative};
use crate::ramp::ramp;

/// One pressure-operated opening: drive ξ = (c·P − p_set)/band, opening ramp(ξ, eps),
/// conductance α at full opening.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Opening {
    /// Its name, published as a signal (and a state's with dynamics): `x`, `x_check`.
    pub name: &'static str,
    /// Orifice coefficient α at full opening, m³/(s·√Pa).
    pub alpha: f64,
    /// The weight of each port's pressure in the drive (dimensionless area ratios).
    pub c: [f64; 3],
    /// The setting p_set, Pa: the weighted pressure at which ξ = 0.
    pub p_set: f64,
    /// The pressure band Δp from closed to fully open, Pa.
    pub band: f64,
    /// Half-width ε of the rounded corners, as a fraction of the band (crate::ramp).
    pub eps: f64,
}

impl Opening {
    /// The static opening and its slope dx/dξ at port pressures `p`.
    fn target(&self, p: &[f64; 3]) -> (f64, f64) {
        let drive = self.c[0] * p[0] + self.c[1] * p[1] + self.c[2] * p[2];
        ramp((drive - self.p_set) / self.band, self.eps)
    }
}

/// Half-width ε of the rounded corners of the opening ([`crate::ramp`]).
pub const SMOOTHING: ParamDecl = ParamDecl::number(
    "smoothing",
    "1",
    "half-width ε of the opening's rounded corners, fraction of its pressure band",
)
.range(Range::closed(0.0, 0.5))
.default(0.05);
/// Simplification of a pressure valve: its closed seat shut tight (`g_leak = 0`).
pub const NO_SEAT_LEAK: Simplification = Simplification::new(
    "no_seat_leak",
    "closed seat tight: g_leak = 0",
    &[Change::Set("g_leak", "0")],
);
/// The seat's leak (every pressure valve of this crate declares these two).
pub const G_LEAK: ParamDecl =
    ParamDecl::number("g_leak", "m³/(s·Pa)", "leak conductance of the closed seat")
        .non_negative()
        .default(1e-15);

/// A pressure-operated valve (see the module documentation for the law).
#[derive(Debug)]
pub struct PressureValve {
    kind: &'static str,
    ports: &'static [&'static str],
    openings: Vec<Opening>,
    g_leak: f64,
    p_tr: f64,
    tau: Option<f64>,
}

impl PressureValve {
    /// A valve of kind `kind` with ports `ports` (two, or three with a pilot), the given
    /// openings (one or two), leak conductance `g_leak` (m³/(s·Pa), ≥ 0), regRoot transition
    /// pressure `p_tr` (Pa, ≥ 0) and optional opening time constant `tau` (s, > 0).
    pub fn new(
        kind: &'static str,
        ports: &'static [&'static str],
        openings: Vec<Opening>,
        g_leak: f64,
        p_tr: f64,
        tau: Option<f64>,
    ) -> Result<Self, ParamError> {
        ParamError::non_negative("g_leak", g_leak)?;
        ParamError::non_negative("p_tr", p_tr)?;
        if let Some(t) = tau {
            ParamError::positive("tau", t)?;
        }
        for o in &openings {
            ParamError::positive("alpha", o.alpha)?;
            ParamError::finite("p_set", o.p_set)?;
            ParamError::positive("band", o.band)?;
            for c in o.c {
                ParamError::finite("c", c)?;
            }
            if !(0.0..=0.5).contains(&o.eps) {
                return Err(ParamError::OutOfRange {
                    param: "smoothing".into(),
                    value: o.eps,
                    requirement: "between 0 and 0.5",
                });
            }
        }
        Ok(Self {
            kind,
            ports,
            openings,
            g_leak,
            p_tr,
            tau,
        })
    }

    /// The openings.
    #[must_use]
    pub fn openings(&self) -> &[Opening] {
        &self.openings
    }

    /// The static openings' total conductance Σ αᵢ·xᵢ at port pressures `p` (pilot last, 0
    /// without one).
    #[must_use]
    pub fn conductance(&self, p: &[f64; 3]) -> f64 {
        self.openings.iter().map(|o| o.alpha * o.target(p).0).sum()
    }

    /// Flow from port 0 to port 1 at port pressures `p` with the static openings.
    #[must_use]
    pub fn flow(&self, p: &[f64; 3]) -> f64 {
        let dp = p[0] - p[1];
        self.conductance(p) * reg_root(dp, self.p_tr) + self.g_leak * dp
    }

    fn pressures(&self, io: &Io<'_>) -> [f64; 3] {
        let mut p = [0.0; 3];
        for (k, pk) in p.iter_mut().enumerate().take(self.ports.len()) {
            *pk = io.e(k, 0);
        }
        p
    }

    /// Opening i now: the state with dynamics, else the static value; and its slope dx/dξ
    /// (0 with dynamics: the flow then depends on the pressures only through Δp).
    fn opening(&self, i: usize, io: &Io<'_>, p: &[f64; 3]) -> (f64, f64) {
        match self.tau {
            Some(_) => (io.states()[i], 0.0),
            None => self.openings[i].target(p),
        }
    }
}

impl Element for PressureValve {
    fn kind(&self) -> &str {
        self.kind
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(self.ports.iter().map(|n| PortSpec::new(n, 1)).collect())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::FlowOut; self.ports.len()]])
    }
    fn states(&self) -> Vec<StateSpec> {
        match self.tau {
            Some(_) => self
                .openings
                .iter()
                .map(|o| StateSpec::new(o.name, 0.0))
                .collect(),
            None => Vec::new(),
        }
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        self.openings
            .iter()
            .map(|o| SignalSpec::scalar(o.name))
            .collect()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let n = self.ports.len();
        let efforts: Vec<Slot> = (0..n).map(Slot::Effort).collect();
        vec![
            Stage {
                writes: (0..n).map(Slot::Flow).collect(),
                reads: efforts.clone(),
            },
            Stage {
                writes: (0..self.openings.len()).map(Slot::Output).collect(),
                reads: if self.tau.is_some() {
                    Vec::new()
                } else {
                    efforts
                },
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let p = self.pressures(io);
        if stage == 0 {
            let dp = p[0] - p[1];
            let mut g = 0.0;
            for (i, o) in self.openings.iter().enumerate() {
                g += o.alpha * self.opening(i, io, &p).0;
            }
            let q = g * reg_root(dp, self.p_tr) + self.g_leak * dp;
            io.set_f_in(0, 0, q);
            io.set_f_in(1, 0, -q);
            if self.ports.len() > 2 {
                io.set_f_in(2, 0, 0.0);
            }
        } else {
            for i in 0..self.openings.len() {
                let x = self.opening(i, io, &p).0;
                io.set_y(i, 0, x);
            }
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        if let Some(tau) = self.tau {
            let p = self.pressures(io);
            for (i, o) in self.openings.iter().enumerate() {
                dx[i] = (o.target(&p).0 - io.states()[i]) / tau;
            }
        }
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let p = self.pressures(io);
        let n = self.ports.len();
        if stage == 0 {
            let dp = p[0] - p[1];
            let (rr, drr) = (reg_root(dp, self.p_tr), reg_root_derivative(dp, self.p_tr));
            // ∂Q/∂P_k = Σᵢ αᵢ·(dxᵢ/dξᵢ)·cᵢₖ/Δpᵢ·rr + (Σᵢ αᵢxᵢ·rr′ + g)·(δ_k0 − δ_k1)
            let mut dq = [0.0; 3];
            let mut g = 0.0;
            for (i, o) in self.openings.iter().enumerate() {
                let (x, slope) = self.opening(i, io, &p);
                g += o.alpha * x;
                for (d, c) in dq.iter_mut().zip(o.c) {
                    *d += o.alpha * slope * c / o.band * rr;
                }
            }
            let through = g * drr + self.g_leak;
            dq[0] += through;
            dq[1] -= through;
            for (port, s) in [(0, 1.0), (1, -1.0)] {
                let row = jac.row(Slot::Flow(port), 0);
                for (k, d) in dq.iter().enumerate().take(n) {
                    jac.set(row, jac.effort_col(k, 0), s * d);
                }
                if self.tau.is_some() {
                    for (i, o) in self.openings.iter().enumerate() {
                        jac.set(row, jac.state_col(i), s * o.alpha * rr);
                    }
                }
            }
        } else {
            for (i, o) in self.openings.iter().enumerate() {
                let row = jac.row(Slot::Output(i), 0);
                if self.tau.is_some() {
                    jac.set(row, jac.state_col(i), 1.0);
                } else {
                    let slope = o.target(&p).1;
                    for k in 0..n {
                        jac.set(row, jac.effort_col(k, 0), slope * o.c[k] / o.band);
                    }
                }
            }
        }
        true
    }
    fn derivative_partials(&self, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let Some(tau) = self.tau else {
            return true;
        };
        let p = self.pressures(io);
        for (i, o) in self.openings.iter().enumerate() {
            let row = jac.derivative_row(i);
            let slope = o.target(&p).1;
            for k in 0..self.ports.len() {
                jac.set(row, jac.effort_col(k, 0), slope * o.c[k] / (o.band * tau));
            }
            jac.set(row, jac.state_col(i), -1.0 / tau);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bondgraph::check_partials;

    fn two_openings(tau: Option<f64>) -> PressureValve {
        let main = Opening {
            name: "x",
            alpha: 2e-7,
            c: [0.0, 1.0, 3.0],
            p_set: 20e6,
            band: 2e6,
            eps: 0.05,
        };
        let check = Opening {
            name: "x_check",
            alpha: 3e-7,
            c: [1.0, -1.0, 0.0],
            p_set: 2e5,
            band: 1e5,
            eps: 0.05,
        };
        PressureValve::new("test", &["a", "b", "X"], vec![main, check], 1e-14, 1e5, tau).unwrap()
    }

    #[test]
    fn partials_match_central_differences_static_and_dynamic() {
        let ports = [(1, 1.0, PortCausality::FlowOut); 3];
        // P_a, P_b, P_X spread over closed, the rounded corners, the linear part and open
        let cases = [
            (1e6, 12e6, 2.5e6),
            (1e6, 12e6, 2.66e6),
            (1e6, 16e6, 1.5e6),
            (12.28e6, 12e6, 0.0),
            (12.25e6, 12e6, 0.0),
            (14e6, 12e6, 5e6),
        ];
        for (pa, pb, px) in cases {
            // per port (P, Q in), then the states
            let v = two_openings(None);
            let point = [pa, 1e-4, pb, -1e-4, px, 0.0];
            assert_eq!(check_partials(&v, &ports, &point), Ok(2), "{pa} {pb} {px}");
            let v = two_openings(Some(0.01));
            let point = [pa, 1e-4, pb, -1e-4, px, 0.0, 0.3, 0.6];
            assert_eq!(check_partials(&v, &ports, &point), Ok(3), "{pa} {pb} {px}");
        }
    }

    #[test]
    fn dissipates_and_conserves_volume() {
        let v = two_openings(None);
        for pa in [0.0, 1e6, 12.1e6, 30e6] {
            for pb in [0.0, 12e6, 25e6] {
                for px in [0.0, 3e6, 9e6] {
                    let q = v.flow(&[pa, pb, px]);
                    assert!(q * (pa - pb) >= 0.0, "{pa} {pb} {px}: {q}");
                }
            }
        }
    }

    #[test]
    fn rejects_bad_openings() {
        let mut o = two_openings(None).openings()[0];
        o.eps = 0.6;
        assert!(PressureValve::new("t", &["a", "b"], vec![o], 0.0, 1e5, None).is_err());
        o.eps = 0.0;
        o.band = 0.0;
        assert!(PressureValve::new("t", &["a", "b"], vec![o], 0.0, 1e5, None).is_err());
        o.band = 1.0;
        assert!(PressureValve::new("t", &["a", "b"], vec![o], -1.0, 1e5, None).is_err());
        assert!(PressureValve::new("t", &["a", "b"], vec![o], 0.0, 1e5, Some(0.0)).is_err());
        assert!(PressureValve::new("t", &["a", "b"], vec![o], 0.0, 1e5, None).is_ok());
    }
}
