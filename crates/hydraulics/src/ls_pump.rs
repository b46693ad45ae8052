//! Load-sensing pump `hydraulics.ls_pump`: a variable-displacement pump whose controller
//! holds its outlet a margin Δp_LS above the load-sense pressure, with a pressure cut-off and
//! an optional torque (power) limiter.
//!
//! The machine is the displacement machine of [`crate::machine`] (`Q = D·ω − C_l·Δp`,
//! `T = D·Δp + T_f(ω)`, the same leakage and friction, so the same efficiencies) with
//! D = ε·D_max and the swash-plate setting ε ∈ [0, 1] a **state** moved by the controller,
//! a first-order servo with its own time constants (the stroking piston; Manring,
//! *Hydraulic Control Systems*, 2005, ch. 8; Ivantysynova & Ivantysyn, *Hydrostatic Pumps
//! and Motors*, 2001, the LS and pressure controllers):
//!
//! ```text
//! dε/dt = (ε* − ε)/τ(ε* − ε)   1/τ(d) = ½(1/τ_up + 1/τ_down) + ½(1/τ_up − 1/τ_down)·tanh(d/0.01)
//! ε* = ramp(ξ_LS)·ramp(ξ_pc)·ramp(ξ_T)                   (crate::ramp: clamp to [0, 1], C¹)
//! ξ_LS = (P_LS + Δp_LS − P_b)/Δp_band                    LS compensator
//! ξ_pc = (p_max − P_b)/Δp_cut                            pressure cut-off
//! ξ_T  = (T_max − ε·D_max·(P_b − P_a))/(0.05·T_max)      torque limiter (optional, else 1)
//! ```
//!
//! The time constant is τ_up on-stroke and τ_down de-stroking (a datasheet's response and
//! return times), blended over 1 % of the stroke around ε* = ε so that the rate is smooth
//! where the pump spends its time, at its equilibrium.
//!
//! Each spool is proportional: the LS compensator de-strokes the pump fully when the
//! outlet is Δp_LS above the load-sense pressure (the **margin**, a datasheet's standby
//! setting, reached at zero stroke), and strokes it fully Δp_band lower; in between the
//! outlet sits at `P_LS + Δp_LS − ε·Δp_band`. In **standby** (every section centred, the LS
//! line drained to tank) the pump delivers only the leaks, ε ≈ 0, and the outlet sits at the
//! margin. The cut-off de-strokes the pump between `p_max − Δp_cut` and `p_max`, so a stalled
//! load is held at p_max with the pump delivering only its leaks. The torque limiter compares
//! the hydraulic torque ε·D_max·Δp with its setting, as a power controller's spool compares
//! pressure times swash angle with its spring; a power limit P at speed ω is
//! `torque_max = P/ω`. The three act in series (the product: each can only de-stroke).
//! ε* ∈ [0, 1], so ε stays in [0, 1] when it starts there.
//!
//! Ports: `a` suction, `b` outlet (both receive their pressure, set their flow), `LS` the
//! load-sense port (senses its pressure, passes no flow), and `shaft` (receives ω, sets the
//! torque the drive applies) — or a set `speed` and no shaft, publishing the signal
//! `torque` as `hydraulics.pump` does. State `eps` (the displacement fraction).
//! Power: the machine's, `P_a·Q − P_b·Q + T·ω = C_l·Δp² + T_f(ω)·ω ≥ 0`; the LS port takes
//! none.

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params, Range};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage, StateSpec,
};

use crate::friction::law_of;
use crate::machine::{self, Machine, Role};
use crate::ramp::ramp;

const PA: usize = 0;
const PB: usize = 1;
const LS: usize = 2;
const SHAFT: usize = 3;

/// The controller's settings (pressures in Pa, times in s, torque in N·m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LsController {
    /// LS margin Δp_LS: outlet over load-sense pressure at zero stroke.
    pub margin: f64,
    /// Pressure drop from zero to full stroke of the LS compensator, Δp_band.
    pub band: f64,
    /// Cut-off pressure p_max (outlet, gauge).
    pub p_max: f64,
    /// Pressure rise from full to zero stroke of the cut-off, Δp_cut.
    pub cut_band: f64,
    /// Torque limit T_max (`None`: no limiter).
    pub torque_max: Option<f64>,
    /// On-stroke time constant τ_up.
    pub tau_up: f64,
    /// De-stroke time constant τ_down.
    pub tau_down: f64,
    /// Half-width ε of the ramps' rounded corners (fraction of each band).
    pub smoothing: f64,
}

impl LsController {
    /// Check the settings; errors name the model-file keys.
    pub fn validate(&self) -> Result<(), ParamError> {
        ParamError::positive("margin", self.margin)?;
        ParamError::positive("dp_band", self.band)?;
        ParamError::positive("p_max", self.p_max)?;
        ParamError::positive("cutoff_band", self.cut_band)?;
        ParamError::positive("tau_up", self.tau_up)?;
        ParamError::positive("tau_down", self.tau_down)?;
        if let Some(t) = self.torque_max {
            ParamError::positive("torque_max", t)?;
        }
        if !(0.0..=0.5).contains(&self.smoothing) {
            return Err(ParamError::OutOfRange {
                param: "smoothing".into(),
                value: self.smoothing,
                requirement: "between 0 and 0.5",
            });
        }
        Ok(())
    }

    /// The target stroke ε* and its partials (∂/∂P_a, ∂/∂P_b, ∂/∂P_LS, ∂/∂ε) at the port
    /// pressures and the stroke ε.
    #[must_use]
    pub fn target(&self, d_max: f64, p_a: f64, p_b: f64, p_ls: f64, eps: f64) -> (f64, [f64; 4]) {
        let (r1, s1) = ramp((p_ls + self.margin - p_b) / self.band, self.smoothing);
        let (r2, s2) = ramp((self.p_max - p_b) / self.cut_band, self.smoothing);
        // ∂ξ/∂(P_a, P_b, P_LS, ε) of each ramp
        let d1 = [0.0, -1.0 / self.band, 1.0 / self.band, 0.0];
        let d2 = [0.0, -1.0 / self.cut_band, 0.0, 0.0];
        let (r3, s3, d3) = match self.torque_max {
            Some(t) => {
                let band = 0.05 * t;
                let dp = p_b - p_a;
                let (r, s) = ramp((t - eps * d_max * dp) / band, self.smoothing);
                let k = d_max / band;
                (r, s, [eps * k, -eps * k, 0.0, -dp * k])
            }
            None => (1.0, 0.0, [0.0; 4]),
        };
        let mut d = [0.0; 4];
        for (k, dk) in d.iter_mut().enumerate() {
            *dk = s1 * d1[k] * r2 * r3 + r1 * s2 * d2[k] * r3 + r1 * r2 * s3 * d3[k];
        }
        (r1 * r2 * r3, d)
    }

    /// The stroke rate dε/dt = d/τ(d) at d = ε* − ε, and its slope in d: τ_up on-stroke,
    /// τ_down de-stroking, blended by tanh over 1 % of the stroke (smooth at ε* = ε).
    #[must_use]
    pub fn rate(&self, d: f64) -> (f64, f64) {
        const BLEND: f64 = 0.01;
        let a = 0.5 * (1.0 / self.tau_up + 1.0 / self.tau_down);
        let b = 0.5 * (1.0 / self.tau_up - 1.0 / self.tau_down);
        let th = (d / BLEND).tanh();
        let k = a + b * th;
        (d * k, k + d * b * (1.0 - th * th) / BLEND)
    }
}

/// A load-sensing pump (see the module documentation).
#[derive(Debug)]
pub struct LsPump {
    machine: Machine,
    d_max: f64,
    control: LsController,
    speed: Option<Param>,
    eps0: f64,
}

impl LsPump {
    /// A load-sensing pump of displacement `d_max` (m³/rad at full stroke) with the machine's
    /// losses from `machine` (its displacement is ignored), the controller `control`, a set
    /// `speed` (`None`: a shaft port) and the initial stroke `eps0` ∈ [0, 1].
    pub fn new(
        machine: Machine,
        d_max: f64,
        control: LsController,
        speed: Option<Param>,
        eps0: f64,
    ) -> Result<Self, ParamError> {
        ParamError::positive("displacement", d_max)?;
        control.validate()?;
        if !(0.0..=1.0).contains(&eps0) {
            return Err(ParamError::OutOfRange {
                param: "eps0".into(),
                value: eps0,
                requirement: "within [0, 1]",
            });
        }
        if let Some(w) = speed.as_ref().and_then(Param::constant) {
            ParamError::finite("speed", w)?;
        }
        Ok(Self {
            machine,
            d_max,
            control,
            speed,
            eps0,
        })
    }

    fn has_shaft(&self) -> bool {
        self.speed.is_none()
    }

    fn omega(&self, io: &Io<'_>) -> f64 {
        match &self.speed {
            Some(w) => w.value(io, 0),
            None => io.f_in(SHAFT, 0),
        }
    }

    fn torque_slot(&self) -> Slot {
        if self.has_shaft() {
            Slot::Effort(SHAFT)
        } else {
            Slot::Output(0)
        }
    }

    /// ε* and its partials at the element's current variables.
    fn target(&self, io: &Io<'_>) -> (f64, [f64; 4]) {
        let eps = io.states()[0];
        self.control
            .target(self.d_max, io.e(PA, 0), io.e(PB, 0), io.e(LS, 0), eps)
    }
}

impl Element for LsPump {
    fn kind(&self) -> &str {
        "hydraulics.ls_pump"
    }
    fn energy_role(&self, _: usize) -> bondgraph::EnergyRole {
        // With a shaft the machine is a transformer whose net power in is its losses
        // (leakage, friction); without one it is driven from outside: a source.
        if self.has_shaft() {
            bondgraph::EnergyRole::Dissipation
        } else {
            bondgraph::EnergyRole::Source
        }
    }
    fn external_power(&self, io: &Io<'_>) -> Option<f64> {
        // Driven at a set speed: the drive's power T·ω.
        if self.has_shaft() {
            return None;
        }
        let d = self.d_max * io.states()[0];
        let omega = self.omega(io);
        let delta = io.e(PA, 0) - io.e(PB, 0);
        Some(self.machine.torque(d, omega, delta) * omega)
    }
    fn ports(&self) -> Ports {
        let mut p = vec![
            PortSpec::new("a", 1),
            PortSpec::new("b", 1),
            PortSpec::new("LS", 1),
        ];
        if self.has_shaft() {
            p.push(PortSpec::new("shaft", 1));
        }
        Ports::Fixed(p)
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        use PortCausality::{EffortOut, FlowOut};
        let mut c = vec![FlowOut, FlowOut, FlowOut];
        if self.has_shaft() {
            c.push(EffortOut);
        }
        CausalRule::Fixed(c)
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![StateSpec::new("eps", self.eps0).nominal(1.0)]
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.speed
            .as_ref()
            .map_or_else(Vec::new, Param::signal_inputs)
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        if self.has_shaft() {
            Vec::new()
        } else {
            vec![SignalSpec::scalar("torque")]
        }
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let mut reads = vec![Slot::Effort(PA), Slot::Effort(PB)];
        if self.has_shaft() {
            reads.push(Slot::Flow(SHAFT));
        }
        reads.extend((0..self.speed.as_ref().map_or(0, Param::n_inputs)).map(Slot::Input));
        vec![
            Stage {
                writes: vec![Slot::Flow(PA), Slot::Flow(PB), Slot::Flow(LS)],
                reads: reads.clone(),
            },
            Stage {
                writes: vec![self.torque_slot()],
                reads,
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let d = self.d_max * io.states()[0];
        let omega = self.omega(io);
        let delta = io.e(PA, 0) - io.e(PB, 0);
        if stage == 0 {
            let q = self.machine.flow(d, omega, delta);
            io.set_f_in(PA, 0, q);
            io.set_f_in(PB, 0, -q);
            io.set_f_in(LS, 0, 0.0);
        } else {
            let t = self.machine.torque(d, omega, delta);
            match self.torque_slot() {
                Slot::Effort(p) => io.set_e(p, 0, t),
                _ => io.set_y(0, 0, t),
            }
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        let eps = io.states()[0];
        let (target, _) = self.target(io);
        dx[0] = self.control.rate(target - eps).0;
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let eps = io.states()[0];
        let d = self.d_max * eps;
        let omega = self.omega(io);
        let delta = io.e(PA, 0) - io.e(PB, 0);
        // (∂y/∂Δ, ∂y/∂ω, ∂y/∂ε) for y = Q (stage 0) or the pump's torque (stage 1)
        let (rows, dy_ddelta, dy_domega, dy_deps): (&[(Slot, f64)], f64, f64, f64) = if stage == 0 {
            (
                &[(Slot::Flow(PA), 1.0), (Slot::Flow(PB), -1.0)],
                self.machine.leakage(),
                d,
                self.d_max * omega,
            )
        } else {
            (
                &[(self.torque_slot(), 1.0)],
                -d,
                self.machine.friction().slope(omega),
                -self.d_max * delta,
            )
        };
        for &(slot, s) in rows {
            let row = jac.row(slot, 0);
            jac.set(row, jac.effort_col(PA, 0), s * dy_ddelta);
            jac.set(row, jac.effort_col(PB, 0), -s * dy_ddelta);
            jac.set(row, jac.state_col(0), s * dy_deps);
            match &self.speed {
                None => jac.set(row, jac.flow_col(SHAFT, 0), s * dy_domega),
                Some(w) => w.partials(io, 0, |i, dw| {
                    jac.set(row, jac.input_col(i, 0), s * dy_domega * dw);
                }),
            }
        }
        true
    }
    fn derivative_partials(&self, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let eps = io.states()[0];
        let (target, d) = self.target(io);
        let k = self.control.rate(target - eps).1;
        let row = jac.derivative_row(0);
        jac.set(row, jac.effort_col(PA, 0), d[0] * k);
        jac.set(row, jac.effort_col(PB, 0), d[1] * k);
        jac.set(row, jac.effort_col(LS, 0), d[2] * k);
        jac.set(row, jac.state_col(0), (d[3] - 1.0) * k);
        true
    }
}

/// Kind `hydraulics.ls_pump`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.ls_pump",
    "load-sensing pump a → b, ports LS (sensed) and shaft (or `speed`): swash plate ε a state, τ·ε̇ = ε* − ε, ε* from the LS margin, the cut-off p_max and an optional torque limit",
    &[
        machine::DISPLACEMENT,
        ParamDecl::number("margin", "Pa", "LS margin Δp_LS: outlet over LS pressure at zero stroke (the standby pressure)")
            .positive()
            .default(2e6),
        ParamDecl::number("dp_band", "Pa", "LS compensator band: the outlet falls this much from zero to full stroke")
            .positive()
            .default(2e5),
        ParamDecl::number("p_max", "Pa", "pressure cut-off: outlet pressure at which the pump is de-stroked").positive(),
        ParamDecl::number("cutoff_band", "Pa", "cut-off band: from full stroke at p_max − cutoff_band to zero at p_max")
            .positive()
            .optional("0.02·p_max"),
        ParamDecl::number("torque_max", "N·m", "torque limiter setting (a power limit P at speed ω: P/ω)")
            .positive()
            .optional("no limiter"),
        ParamDecl::number("tau_up", "s", "controller time constant on-stroke (\"40 ms\")")
            .positive()
            .default(0.04),
        ParamDecl::number("tau_down", "s", "controller time constant de-stroking")
            .positive()
            .optional("tau_up"),
        ParamDecl::number("eps0", "1", "initial displacement fraction ε")
            .range(Range::FRACTION)
            .default(0.0),
        ParamDecl::number("smoothing", "1", "half-width of the controller ramps' rounded corners, fraction of each band")
            .range(Range::closed(0.0, 0.5))
            .default(0.05),
        machine::C_L,
        machine::T_C,
        machine::T_S,
        machine::OMEGA_S,
        machine::OMEGA_TANH,
        machine::B,
        machine::SPEED,
    ],
    build,
)
.example("displacement = \"45 cc/rev\", speed = \"1500 rpm\", margin = \"20 bar\", p_max = \"250 bar\"");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    let d_max = p.number("displacement")?;
    let p_max = p.number("p_max")?;
    let tau_up = p.number("tau_up")?;
    let control = LsController {
        margin: p.number("margin")?,
        band: p.number("dp_band")?,
        p_max,
        cut_band: p.optional("cutoff_band")?.unwrap_or(0.02 * p_max),
        torque_max: p.optional("torque_max")?,
        tau_up,
        tau_down: p.optional("tau_down")?.unwrap_or(tau_up),
        smoothing: p.number("smoothing")?,
    };
    let speed = if p.has("speed") {
        Some(p.modulated("speed")?)
    } else {
        None
    };
    let friction = law_of(p, ["t_c", "t_s", "omega_s", "omega_tanh", "b"])?;
    let m = Machine::new(Role::Pump, d_max)?
        .with_leakage(p.number("c_l")?)?
        .with_friction(friction);
    Ok(Box::new(LsPump::new(
        m,
        d_max,
        control,
        speed,
        p.number("eps0")?,
    )?))
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact zeros and ones of the clamped ramps are meant exactly
mod tests {
    use super::*;
    use crate::FrictionLaw;
    use bondgraph::check_partials;
    use PortCausality::{EffortOut, FlowOut};

    /// 45 cm³/rev.
    const D: f64 = 45e-6 / (2.0 * std::f64::consts::PI);

    fn control(torque_max: Option<f64>) -> LsController {
        LsController {
            margin: 20e5,
            band: 2e5,
            p_max: 250e5,
            cut_band: 5e5,
            torque_max,
            tau_up: 0.04,
            tau_down: 0.02,
            smoothing: 0.05,
        }
    }

    fn pump(speed: Option<Param>, torque_max: Option<f64>) -> LsPump {
        let m = Machine::new(Role::Pump, D)
            .unwrap()
            .with_leakage(2e-12)
            .unwrap()
            .with_friction(FrictionLaw::coulomb_viscous(3.0, 0.5, 2e-3).unwrap());
        LsPump::new(m, D, control(torque_max), speed, 0.0).unwrap()
    }

    #[test]
    fn target_stroke_is_the_hand_law() {
        let c = control(None);
        // LS compensator: zero stroke at the margin, full Δp_band below, linear between
        assert_eq!(c.target(D, 0.0, 120.2e5, 100e5, 0.3).0, 0.0);
        assert_eq!(c.target(D, 0.0, 117e5, 100e5, 0.3).0, 1.0);
        let e = c.target(D, 0.0, 119.4e5, 100e5, 0.3).0;
        assert!((e - 0.3).abs() < 1e-12, "{e}");
        // cut-off: with the LS port at the outlet pressure, ε* = (p_max − P_b)/Δp_cut
        let e = c.target(D, 0.0, 248e5, 248e5, 0.3).0;
        assert!((e - 0.4).abs() < 1e-12, "{e}");
        assert_eq!(c.target(D, 0.0, 251e5, 260e5, 0.3).0, 0.0);
        // torque limiter: ε·D·Δp = T_max − 0.05·T_max·ξ; at Δp = 200 bar, ε = 0.5: T = 71.6 N·m
        let t = 0.5 * D * 200e5;
        let c = control(Some(t));
        let e = c.target(D, 0.0, 200e5, 220e5, 0.5).0; // LS and cut-off wide open
                                                       // exactly at the setting the ramp is at its lower corner: ramp(0) = ε/4
        assert!((e - 0.05 / 4.0).abs() < 1e-12, "{e}");
        let e = c.target(D, 0.0, 200e5, 220e5, 0.4).0; // below the limit by 20 %: ξ = 4
        assert!((e - 1.0).abs() < 1e-12, "{e}");
    }

    #[test]
    fn stroke_rate_uses_each_time_constant_and_is_smooth() {
        let c = control(None); // τ_up = 40 ms, τ_down = 20 ms
                               // well away from equilibrium: d/τ_up on-stroke, d/τ_down de-stroking
        assert!((c.rate(0.5).0 - 0.5 / 0.04).abs() < 1e-9);
        assert!((c.rate(-0.5).0 + 0.5 / 0.02).abs() < 1e-9);
        // at equilibrium the mean rate constant, and the slope matches differences
        assert_eq!(c.rate(0.0).0, 0.0);
        for d in [-0.02, -0.004, 0.0, 0.003, 0.05] {
            let h = 1e-7;
            let fd = (c.rate(d + h).0 - c.rate(d - h).0) / (2.0 * h);
            assert!((fd - c.rate(d).1).abs() < 1e-5 * fd.abs(), "{d}: {fd}");
        }
    }

    #[test]
    fn flow_and_torque_are_the_machine_law() {
        // the machine at stroke ε: Q = ε·D·ω − C_l·Δp, T = ε·D·Δp + T_f(ω)
        let p = pump(Some(Param::Const(157.0)), None);
        let (eps, w, dp) = (0.6, 157.0, 180e5);
        let q = p.machine.flow(eps * D, w, -dp);
        assert!((q - (eps * D * w - 2e-12 * dp)).abs() < 1e-15);
        let t = p.machine.torque(eps * D, w, -dp);
        let t_f = 3.0 * (w / 0.5).tanh() + 2e-3 * w;
        assert!((t - (eps * D * dp + t_f)).abs() < 1e-9);
    }

    #[test]
    fn partials_match_central_differences() {
        for torque in [None, Some(60.0)] {
            let p = pump(None, torque);
            let ports = [
                (1, 1.0, FlowOut),
                (1, -1.0, FlowOut),
                (1, 1.0, FlowOut),
                (1, 1.0, EffortOut),
            ];
            // P_a, Q_a, P_b, Q_b, P_LS, Q_LS, T, ω, then ε: on the LS ramp, at the cut-off,
            // on-stroke and de-stroking, and in the torque limiter's band
            for (pb, pls, w, eps) in [
                (119.4e5, 100e5, 150.0, 0.5),
                (119.4e5, 100e5, 150.0, 0.3),
                (247.7e5, 248e5, 150.0, 0.6),
                (50e5, 40e5, 150.0, 0.95),
                (121e5, 100e5, -20.0, 0.2),
                (200e5, 210e5, 150.0, 0.332),
            ] {
                let point = [1e5, 1e-4, pb, 1e-4, pls, 0.0, 10.0, w, eps];
                assert_eq!(
                    check_partials(&p, &ports, &point),
                    Ok(3),
                    "{torque:?} {pb} {pls} {eps}"
                );
            }
        }
        // at a modulated set speed: no shaft, the torque is a signal
        let speed = Param::modulated(vec!["w".into()], |_, u| 100.0 * u[0]);
        let p = pump(Some(speed), Some(60.0));
        let ports = [(1, 1.0, FlowOut), (1, -1.0, FlowOut), (1, 1.0, FlowOut)];
        let point = [1e5, 1e-4, 119e5, 1e-4, 100e5, 0.0, 1.5, 0.4];
        assert_eq!(check_partials(&p, &ports, &point), Ok(3));
    }

    #[test]
    fn rejects_bad_settings() {
        let m = || Machine::new(Role::Pump, D).unwrap();
        let mut c = control(None);
        assert!(LsPump::new(m(), D, c, None, 1.2).is_err());
        assert!(LsPump::new(m(), 0.0, c, None, 0.0).is_err());
        c.margin = 0.0;
        assert!(LsPump::new(m(), D, c, None, 0.0).is_err());
        let mut c = control(Some(-1.0));
        assert!(LsPump::new(m(), D, c, None, 0.0).is_err());
        c.torque_max = None;
        c.smoothing = 0.7;
        assert!(LsPump::new(m(), D, c, None, 0.0).is_err());
    }
}
