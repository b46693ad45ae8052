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
//!
//! **Options** ([`with_fluid`](Chamber::with_fluid), off by default, and then the law above is
//! evaluated exactly as written): entrained air makes the modulus a function of pressure,
//! β_eff(p), and cavitation adds a cavity compliance C_cav(p) near the vapour pressure (the
//! laws in [`crate::fluid`]). The law becomes
//!
//! ```text
//! dP/dt = f_in / (V(s)/β_eff(P) + C_cav(P))
//! ```
//!
//! and the balance `∫Q_in dt = ΔV + ∫V/β_eff dP − ΔV_cav`. With cavitation the pressure stays
//! above the vapour pressure, the chamber also publishes `V_cav` (m³), and the minimum
//! pressure is still recorded but no longer warned about.

use crate::fluid::{self, Cavitation, EntrainedAir, Fluid, FluidOptions};
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
/// * optional entrained air and cavitation: [`with_fluid`](Self::with_fluid).
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
    /// `None`: the constant-β law, evaluated as eq. 28 writes it.
    fluid: Option<Fluid>,
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
            fluid: None,
        })
    }

    /// Entrained air and cavitation (see [`crate::fluid`] and [`FluidOptions`]); nothing
    /// changes if no option is on. The cavity's reference volume is the chamber's volume at
    /// s = 0 (not below `v_min`). With cavitation, the initial pressure must lie above the
    /// vapour pressure.
    pub fn with_fluid(mut self, options: FluidOptions) -> Result<Self, ParamError> {
        let p_atm = ParamError::positive("p_atm", options.p_atm)?;
        let air = match options.air {
            Some((fraction, n)) => Some(EntrainedAir::new(fraction, p_atm, n)?),
            None => None,
        };
        let cavitation = match options.cavitation {
            Some((p_v, p_c)) => {
                let c = Cavitation::new(p_v, p_c, self.v0.max(self.v_min))?;
                if self.p0 + p_atm <= p_v {
                    return Err(ParamError::OutOfRange {
                        param: "p0".into(),
                        value: self.p0,
                        requirement: "above the vapour pressure: p0 + p_atm > p_vapour",
                    });
                }
                Some(c)
            }
            None => None,
        };
        self.fluid = options.any().then_some(Fluid {
            beta: self.beta,
            p_atm,
            air,
            cavitation,
        });
        Ok(self)
    }

    /// Set the smallest volume used, m³ (> 0).
    pub fn with_v_min(mut self, v_min: f64) -> Result<Self, ParamError> {
        self.v_min = ParamError::positive("v_min", v_min)?;
        let v_ref = self.v0.max(self.v_min);
        if let Some(c) = self.fluid.as_mut().and_then(|f| f.cavitation.as_mut()) {
            *c = c.with_v_ref(v_ref);
        }
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

    /// Whether cavitation is represented.
    #[must_use]
    pub fn cavitates(&self) -> bool {
        self.fluid.is_some_and(|f| f.cavitation.is_some())
    }

    /// The fluid options, if any (`None`: constant β).
    #[must_use]
    pub fn fluid(&self) -> Option<&Fluid> {
        self.fluid.as_ref()
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
        if self.cavitates() {
            vec![SignalSpec::scalar("V"), SignalSpec::scalar("V_cav")]
        } else {
            vec![SignalSpec::scalar("V")]
        }
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        // The pressure is the state: it never waits for the stroke.
        let mut first = vec![Slot::Effort(0)];
        if self.cavitates() {
            first.push(Slot::Output(1));
        }
        vec![
            Stage {
                writes: first,
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
            if let Some(f) = self.fluid.filter(|f| f.cavitation.is_some()) {
                io.set_y(1, 0, f.cavity(p).0);
            }
        } else {
            let v = self.volume(self.stroke.value(io, 0));
            io.set_y(0, 0, v);
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        let v = self.volume(self.stroke.value(io, 0));
        dx[0] = match &self.fluid {
            None => self.beta / v * io.f_in(0, 0),
            Some(f) => f.gain(io.states()[0], v).0 * io.f_in(0, 0),
        };
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        if stage == 0 {
            jac.set(jac.row(Slot::Effort(0), 0), jac.state_col(0), 1.0);
            if let Some(f) = self.fluid.filter(|f| f.cavitation.is_some()) {
                let d = f.cavity(io.states()[0]).1;
                jac.set(jac.row(Slot::Output(1), 0), jac.state_col(0), d);
            }
        } else {
            let dv_ds = self.volume_slope(self.stroke.value(io, 0));
            let row = jac.row(Slot::Output(0), 0);
            self.stroke
                .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), dv_ds * d));
        }
        true
    }
    fn derivative_partials(&self, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        // dP/dt = β/V(s)·f_in, or g(P, V(s))·f_in with the fluid options
        let s = self.stroke.value(io, 0);
        let v = self.volume(s);
        let row = jac.derivative_row(0);
        let f_in = io.f_in(0, 0);
        let dd_ds = if let Some(f) = &self.fluid {
            let (g, dg_dp, dg_dv) = f.gain(io.states()[0], v);
            jac.set(row, jac.flow_col(0, 0), g);
            jac.set(row, jac.state_col(0), dg_dp * f_in);
            dg_dv * f_in * self.volume_slope(s)
        } else {
            jac.set(row, jac.flow_col(0, 0), self.beta / v);
            -self.beta * f_in / (v * v) * self.volume_slope(s)
        };
        self.stroke
            .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), dd_ds * d));
        true
    }
    fn watches(&self) -> Vec<Watch> {
        if self.cavitates() {
            return vec![Watch {
                name: "pressure".into(),
                state: 0,
                warn_below: None,
                warning: String::new(),
            }];
        }
        vec![Watch {
            name: "pressure".into(),
            state: 0,
            // Undershoots within the solver's tolerance band are not cavitation.
            warn_below: Some(self.p_tank - 1e-6 * self.p_nominal),
            warning: "cavitation, which the model does not represent (set `cavitation = true` on the chamber or its cylinder to represent it)".into(),
        }]
    }
}

/// Kind `hydraulics.chamber`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.chamber",
    "oil volume, C with pressure state: dP/dt = β/V(s)·Q, V = A(l⁰ ± s) or fixed; publishes V; options: entrained air, cavitation",
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
        fluid::AIR_FRACTION,
        fluid::N_AIR,
        fluid::CAVITATION,
        fluid::P_VAPOUR,
        fluid::P_CAV_BAND,
        fluid::P_ATM,
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
        .with_nominal_pressure(p.number("p_nominal")?)?
        .with_fluid(fluid::options(p)?)?;
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
    fn partials_with_air_and_cavitation_match_central_differences() {
        use bondgraph::check_partials;
        let stroke = || Param::modulated(vec!["s".into()], |_, u| u[0]);
        let options = FluidOptions {
            air: Some((0.005, 1.3)),
            cavitation: Some((2e3, 1e3)),
            ..FluidOptions::default()
        };
        let p = Chamber::cylinder(Side::Piston, 0.045, 0.05, 1.5e9, stroke(), 0.0)
            .unwrap()
            .with_fluid(options)
            .unwrap();
        let air_only = FluidOptions {
            cavitation: None,
            ..options
        };
        let r = Chamber::cylinder(Side::Rod, 0.042, 2.75, 1.5e9, stroke(), 0.0)
            .unwrap()
            .with_fluid(air_only)
            .unwrap();
        let port = [(1, 1.0, PortCausality::EffortOut)];
        // P, Q_in, s, P (state): from deep in the cavitation band to 20 MPa
        // (not where e^(−x) is ~1e-50: its differences lose their digits there)
        for pressure in [-9.6e4, -9e4, -5e4, 0.0, 1e6, 2e7] {
            for s in [0.6, 2.9] {
                let point = [0.0, 2e-3, s, pressure];
                if pressure != 0.0 {
                    assert_eq!(check_partials(&p, &port, &point), Ok(3), "{pressure} {s}");
                }
                assert_eq!(check_partials(&r, &port, &point), Ok(3), "{pressure} {s}");
            }
        }
    }

    #[test]
    fn options_off_leave_the_chamber_as_it_was() {
        let c = Chamber::fixed(1e-3, 1.5e9, 2e6)
            .unwrap()
            .with_fluid(FluidOptions::default())
            .unwrap();
        assert!(c.fluid().is_none() && !c.cavitates());
        assert_eq!(c.signal_outputs().len(), 1);
        // a start at or below the vapour pressure is refused
        let cav = FluidOptions {
            cavitation: Some((2e3, 1e3)),
            ..FluidOptions::default()
        };
        assert!(Chamber::fixed(1e-3, 1.5e9, -1e5)
            .unwrap()
            .with_fluid(cav)
            .is_err());
        let c = Chamber::fixed(1e-3, 1.5e9, 0.0)
            .unwrap()
            .with_fluid(cav)
            .unwrap();
        assert!(c.cavitates());
        assert_eq!(c.watches()[0].warn_below, None);
        assert_eq!(c.signal_outputs()[1].name, "V_cav");
    }

    /// A 1 l chamber at 1 MPa emptied at 0.1 l/s for 1 s: the oil decompresses in 7 ms, then
    /// a cavity opens and grows to 10 % of the volume while the pressure stays above p_v.
    #[test]
    fn emptied_chamber_cavitates_above_the_vapour_pressure_and_keeps_its_volume() {
        use bondgraph::{
            assign_causality, simulate, BondGraph, FlowSource, Output, Settings, StateEquations,
        };
        let (v, beta, p0, q, p_atm, p_v, p_c) = (1e-3, 1.5e9, 1e6, 1e-4, 101_325.0, 2e3, 1e3);
        let options = FluidOptions {
            p_atm,
            air: None,
            cavitation: Some((p_v, p_c)),
        };
        let chamber = Chamber::fixed(v, beta, p0)
            .unwrap()
            .with_fluid(options)
            .unwrap();
        let fluid = *chamber.fluid().unwrap();
        let mut g = BondGraph::new();
        g.add("oil", chamber).unwrap();
        g.add("drain", FlowSource::new(-q)).unwrap();
        g.connect_names("drain", "oil").unwrap();
        let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        let outputs: Vec<Output> = [("p", "oil.p"), ("v_cav", "oil.V_cav")]
            .iter()
            .map(|(n, p)| Output {
                name: (*n).into(),
                probe: eqs.probe(p).unwrap(),
            })
            .collect();
        let settings = Settings {
            t_end: 1.0,
            dt_out: 1e-3,
            rtol: 1e-8,
            atol: 1e-8,
            ..Settings::default()
        };
        let x0 = eqs.initial_state();
        let run = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
        assert!(run.error.is_none(), "{:?}", run.error);
        let tr = &run.trajectory;
        let (t, p, v_cav) = (
            tr.column("t").unwrap(),
            tr.column("p").unwrap(),
            tr.column("v_cav").unwrap(),
        );
        let v_cav0 = fluid.cavity(p0).0;
        let mut worst: f64 = 0.0;
        for k in 0..t.len() {
            assert!(p[k] + p_atm > p_v, "t = {}: p_abs = {}", t[k], p[k] + p_atm);
            // ∫Q_in dt = (V/β)·ΔP − ΔV_cav
            let inflow = -q * t[k];
            let stored = v / beta * (p[k] - p0) - (v_cav[k] - v_cav0);
            worst = worst.max((inflow - stored).abs());
        }
        let last = t.len() - 1;
        eprintln!(
            "cavity {:.4e} m³, p_abs − p_v = {:.1} Pa at t = 1 s; worst imbalance {worst:.2e} m³",
            v_cav[last],
            p[last] + p_atm - p_v
        );
        assert!(v_cav[last] > 0.09 * v, "the cavity grew: {}", v_cav[last]);
        // measured 8e-7 of the outflow (rtol 1e-8)
        assert!(worst < 1e-5 * q * t[last], "imbalance {worst:e} m³");
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
