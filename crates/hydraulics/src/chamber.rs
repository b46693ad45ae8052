//! Chamber `hydraulics.chamber`: a volume of compressible oil, a `C` element whose state is
//! its *pressure* and whose compliance V/β follows the piston stroke (paper eqs. 27–28, 78–79).
//!
//! ```text
//! V(s)  = max(V₀ + (dV/ds)·s, V_min)     piston side: V₀ = A·l⁰, dV/ds = +A
//!                                         rod side:    V₀ = A·l⁰, dV/ds = −A
//! dP/dt = β/V(s) · f_in
//! ```
//!
//! `f_in` is the net flow into the chamber's port. The chamber sits on a 0-junction that also
//! carries the piston's transformer bond, whose flow is ±A·ṡ = dV/dt; so f_in = Q_in − dV/dt,
//! and the law is eq. 28, `(V/β)·Ṗ + dV/dt = Q_in`. This is a *modulated* C with a pressure
//! state. It is not energy-conserving by itself (the modulation of V/β does work that the
//! port does not see) — but the fluid volume balances: over a run,
//! `∫Q_in dt = ΔV + ∫(V/β) dP`, which `tests/volume_bookkeeping.rs` checks. (The core `C` with
//! a modulated compliance would integrate the displacement q = (V/β)·P instead, and would
//! count the P·dV/β term twice.)
//!
//! `V_min` > 0 keeps the volume from reaching zero: past the end of the stroke (a drive on
//! its end stop with zero dead length) the volume is held at V_min. Leaving the stroke range
//! is reported by the [`Piston`](crate::Piston), not here.
//!
//! Causality: integral (the chamber sets its pressure); derivative causality is refused.
//! The chamber publishes `V` (its volume, m³), and asks the simulator to watch its minimum
//! pressure, warning when it fell below the tank pressure (cavitation is not modelled) by
//! more than 1e-6 of the nominal pressure (1 Pa by default): smaller undershoots are the
//! solver's tolerance, not cavitation.

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage, StateSpec, Watch,
};

/// Which end of the cylinder a chamber is on: how its volume follows the stroke s.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// Piston (cap) side: V = A·(l⁰ + s).
    Piston,
    /// Rod (annulus) side: V = A·(l⁰ − s).
    Rod,
}

/// A hydraulic chamber with a pressure state.
///
/// * `v0` — volume at stroke s = 0, m³, ≥ 0; `dv_ds` — volume per stroke, m² (±A, or 0 for a
///   fixed volume); `stroke` — the stroke s, m (a signal, usually `<piston>.s`).
/// * `beta` — bulk modulus β, Pa, > 0.
/// * `v_min` — smallest volume used, m³, > 0.
/// * `p0` — initial pressure, Pa; `p_tank` — tank pressure, Pa, for the cavitation warning.
#[derive(Debug)]
pub struct Chamber {
    v0: f64,
    dv_ds: f64,
    stroke: Param,
    beta: f64,
    v_min: f64,
    p0: f64,
    p_tank: f64,
    p_nominal: f64,
}

impl Chamber {
    /// A cylinder chamber of area `area` (m²) and dead length `dead_length` (m, the chamber's
    /// length at s = 0) on `side`, its volume following `stroke`. `v_min` defaults to 1e-3 of
    /// the dead volume A·l⁰ (to A·1 µm when l⁰ = 0); set it with [`with_v_min`](Self::with_v_min).
    pub fn cylinder(
        side: Side,
        area: f64,
        dead_length: f64,
        beta: f64,
        stroke: impl Into<Param>,
        p0: f64,
    ) -> Result<Self, ParamError> {
        ParamError::positive("area", area)?;
        ParamError::non_negative("dead_length", dead_length)?;
        let dv_ds = match side {
            Side::Piston => area,
            Side::Rod => -area,
        };
        Self::build(area * dead_length, dv_ds, stroke.into(), beta, p0)
    }

    /// A chamber of constant volume `volume` (m³): a hose, a pipe, an accumulator's oil.
    pub fn fixed(volume: f64, beta: f64, p0: f64) -> Result<Self, ParamError> {
        ParamError::positive("volume", volume)?;
        Self::build(volume, 0.0, Param::Const(0.0), beta, p0)
    }

    fn build(v0: f64, dv_ds: f64, stroke: Param, beta: f64, p0: f64) -> Result<Self, ParamError> {
        ParamError::positive("beta", beta)?;
        ParamError::finite("p0", p0)?;
        if let Some(s) = stroke.constant() {
            ParamError::finite("stroke", s)?;
        }
        Ok(Self {
            v0,
            dv_ds,
            stroke,
            beta,
            v_min: if v0 > 0.0 {
                1e-3 * v0
            } else {
                1e-6 * dv_ds.abs()
            },
            p0,
            p_tank: 0.0,
            p_nominal: 1e6,
        })
    }

    /// Set the smallest volume used, m³ (> 0).
    pub fn with_v_min(mut self, v_min: f64) -> Result<Self, ParamError> {
        self.v_min = ParamError::positive("v_min", v_min)?;
        Ok(self)
    }

    /// Set the tank pressure below which the run ends with a cavitation warning (Pa).
    pub fn with_tank_pressure(mut self, p_tank: f64) -> Result<Self, ParamError> {
        self.p_tank = ParamError::finite("p_tank", p_tank)?;
        Ok(self)
    }

    /// Set the typical pressure magnitude, Pa: the absolute tolerance of the pressure state is
    /// `atol · p_nominal` (default 1e6 Pa).
    pub fn with_nominal_pressure(mut self, p_nominal: f64) -> Result<Self, ParamError> {
        self.p_nominal = ParamError::positive("p_nominal", p_nominal)?;
        Ok(self)
    }

    /// Volume at stroke `s` (m³), not below `v_min`.
    #[must_use]
    pub fn volume(&self, s: f64) -> f64 {
        (self.v0 + self.dv_ds * s).max(self.v_min)
    }

    /// dV/ds at stroke `s`: `dv_ds`, or 0 where the volume is held at `v_min`.
    fn volume_slope(&self, s: f64) -> f64 {
        if self.v0 + self.dv_ds * s < self.v_min {
            0.0
        } else {
            self.dv_ds
        }
    }
}

impl Element for Chamber {
    fn kind(&self) -> &str {
        "hydraulics.chamber"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Integral(vec![PortCausality::EffortOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![StateSpec::new("p", self.p0).nominal(self.p_nominal)]
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.stroke.signal_inputs()
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("V")]
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        // The pressure is the state: it never waits for the stroke.
        vec![
            Stage {
                writes: vec![Slot::Effort(0)],
                reads: Vec::new(),
            },
            Stage {
                writes: vec![Slot::Output(0)],
                reads: (0..self.stroke.n_inputs()).map(Slot::Input).collect(),
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        if stage == 0 {
            let p = io.states()[0];
            io.set_e(0, 0, p);
        } else {
            let v = self.volume(self.stroke.value(io, 0));
            io.set_y(0, 0, v);
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        let v = self.volume(self.stroke.value(io, 0));
        dx[0] = self.beta / v * io.f_in(0, 0);
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        if stage == 0 {
            jac.set(jac.row(Slot::Effort(0), 0), jac.state_col(0), 1.0);
        } else {
            let dv_ds = self.volume_slope(self.stroke.value(io, 0));
            let row = jac.row(Slot::Output(0), 0);
            self.stroke
                .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), dv_ds * d));
        }
        true
    }
    fn derivative_partials(&self, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        // dP/dt = β/V(s)·f_in
        let s = self.stroke.value(io, 0);
        let v = self.volume(s);
        let row = jac.derivative_row(0);
        jac.set(row, jac.flow_col(0, 0), self.beta / v);
        let dd_ds = -self.beta * io.f_in(0, 0) / (v * v) * self.volume_slope(s);
        self.stroke
            .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), dd_ds * d));
        true
    }
    fn watches(&self) -> Vec<Watch> {
        vec![Watch {
            name: "pressure".into(),
            state: 0,
            // Undershoots within the solver's tolerance band are not cavitation.
            warn_below: Some(self.p_tank - 1e-6 * self.p_nominal),
            warning: "cavitation, which the model does not represent".into(),
        }]
    }
}

/// Kind `hydraulics.chamber`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.chamber",
    "oil volume, C with pressure state: dP/dt = β/V(s)·Q, V = A(l⁰ ± s) or fixed; publishes V",
    &[
        ParamDecl::choice(
            "side",
            &["piston", "rod"],
            "piston",
            "which side of the piston the chamber is on",
        ),
        ParamDecl::number("area", "m²", "piston or annulus area")
            .positive()
            .optional("give `volume` instead"),
        ParamDecl::number("dead_length", "m", "chamber length at s = 0")
            .non_negative()
            .optional("give `volume` instead"),
        ParamDecl::modulated("stroke", "m", "stroke signal, e.g. \"cyl.s\"")
            .optional("give `volume` instead"),
        ParamDecl::number(
            "volume",
            "m³",
            "a fixed volume (hose, pipe) instead of area, dead_length, stroke",
        )
        .positive()
        .optional("a cylinder chamber"),
        ParamDecl::number("beta", "Pa", "bulk modulus β").positive(),
        ParamDecl::number("p0", "Pa", "initial pressure").default(0.0),
        ParamDecl::number("v_min", "m³", "smallest volume used")
            .positive()
            .optional("1e-3 of A·l⁰, or A·1 µm if l⁰ = 0"),
        ParamDecl::number("p_tank", "Pa", "tank pressure for the cavitation warning").default(0.0),
        ParamDecl::number("p_nominal", "Pa", "tolerance scale of the pressure state")
            .positive()
            .default(1e6),
    ],
    build,
)
.example("volume = 1e-3, beta = 1.5e9, p0 = 1e6");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    let beta = p.number("beta")?;
    let p0 = p.number("p0")?;
    let c = if p.has("volume") {
        for k in ["area", "dead_length", "stroke", "side"] {
            if p.has(k) {
                return Err(BuildError::conflict(k, format!("give either `volume` or `area`, `dead_length` and `stroke`, not `{k}` with `volume`")));
            }
        }
        Chamber::fixed(p.number("volume")?, beta, p0)
    } else {
        let side = if p.word("side")? == "rod" {
            Side::Rod
        } else {
            Side::Piston
        };
        Chamber::cylinder(
            side,
            p.number("area")?,
            p.number("dead_length")?,
            beta,
            p.modulated("stroke")?,
            p0,
        )
    };
    let mut c = c?;
    if let Some(v) = p.optional("v_min")? {
        c = c.with_v_min(v)?;
    }
    let c = c
        .with_tank_pressure(p.number("p_tank")?)?
        .with_nominal_pressure(p.number("p_nominal")?)?;
    Ok(Box::new(c))
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact zeros and copied parameters are meant exactly
mod tests {
    use super::*;

    #[test]
    fn volume_follows_the_stroke_and_stops_at_v_min() {
        let p = Chamber::cylinder(Side::Piston, 0.04, 0.05, 1.5e9, 0.0, 0.0).unwrap();
        let r = Chamber::cylinder(Side::Rod, 0.03, 2.75, 1.5e9, 0.0, 0.0).unwrap();
        assert!((p.volume(1.0) - 0.04 * 1.05).abs() < 1e-15);
        assert!((r.volume(1.0) - 0.03 * 1.75).abs() < 1e-15);
        assert!(
            (p.volume(-1.0) - 1e-3 * 0.04 * 0.05).abs() < 1e-18,
            "held at v_min"
        );
        let f = Chamber::fixed(2e-3, 1.5e9, 0.0).unwrap();
        assert!((f.volume(123.0) - 2e-3).abs() < 1e-18);
    }

    #[test]
    fn partials_match_central_differences() {
        use bondgraph::check_partials;
        let stroke = || Param::modulated(vec!["s".into()], |_, u| u[0]);
        let p = Chamber::cylinder(Side::Piston, 0.045, 0.05, 1.5e9, stroke(), 0.0).unwrap();
        let r = Chamber::cylinder(Side::Rod, 0.042, 2.75, 1.5e9, stroke(), 0.0).unwrap();
        let port = [(1, 1.0, PortCausality::EffortOut)];
        // P, Q_in, s, P (state)
        for c in [&p, &r] {
            for s in [0.6, -0.3, 2.9] {
                let point = [0.0, 2e-3, s, 5e6];
                assert_eq!(check_partials(c, &port, &point), Ok(3), "{s}");
            }
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(Chamber::cylinder(Side::Piston, 0.0, 0.05, 1.5e9, 0.0, 0.0).is_err());
        assert!(Chamber::cylinder(Side::Piston, 0.04, -0.05, 1.5e9, 0.0, 0.0).is_err());
        assert!(Chamber::cylinder(Side::Piston, 0.04, 0.05, 0.0, 0.0, 0.0).is_err());
        assert!(Chamber::cylinder(Side::Piston, 0.04, 0.05, 1.5e9, 0.0, f64::NAN).is_err());
        // zero dead length: v_min defaults to the volume of 1 µm of stroke
        let c = Chamber::cylinder(Side::Piston, 0.04, 0.0, 1.5e9, 0.0, 0.0).unwrap();
        assert!((c.volume(0.0) - 0.04e-6).abs() < 1e-20);
        assert!(c.with_v_min(0.0).is_err());
        assert!(Chamber::fixed(-1.0, 1.5e9, 0.0).is_err());
    }

    #[test]
    fn watches_its_pressure_against_the_tank() {
        let c = Chamber::fixed(1e-3, 1.5e9, 2e6)
            .unwrap()
            .with_tank_pressure(1e5)
            .unwrap();
        let w = c.watches();
        assert_eq!(w.len(), 1);
        assert_eq!(w[0].state, 0);
        assert_eq!(w[0].warn_below, Some(1e5 - 1.0));
        assert_eq!(c.states()[0].nominal, 1e6);
    }
}
