//! Displacement machines: pump `hydraulics.pump` and motor `hydraulics.motor`, one law.
//!
//! A positive-displacement machine of displacement D = ε·D_max (m³/rad; ε the displacement
//! fraction, the swash-plate setting of a variable machine, clamped to [−1, 1]) is a
//! transformer between the shaft (torque T, speed ω) and the oil (pressure difference Δp,
//! flow Q), `Q = D·ω`, `T = D·Δp`, with two losses (Merritt, "Hydraulic Control Systems",
//! 1967, ch. 6; Manring, "Hydraulic Control Systems", 2005, ch. 7; Jelali & Kroll,
//! "Hydraulic Servo-systems", 2003, sec. 3.3):
//!
//! * volumetric: laminar leakage across the machine, `Q_leak = C_l·Δp`;
//! * hydromechanical: a friction torque `T_f(ω)` ([`FrictionLaw`]: regularised Coulomb
//!   `T_c·tanh(ω/ω_tanh)`, optional Stribeck peak, viscous `b·ω`).
//!
//! With Δ = P_a − P_b and the shaft speed ω (sign conventions below), both kinds are
//!
//! ```text
//! Q = D·ω + C_l·Δ                    flow through the machine from a to b
//! T_shaft = D·Δ − T_f(ω)   (motor)   torque delivered to the load
//! T_shaft = D·(−Δ) + T_f(ω) (pump)   torque the drive must apply
//! ```
//!
//! **Sign conventions** (power in positive, `docs/conventions.md`).
//! * Pump: `a` is the inlet (suction, low), `b` the outlet (delivery, high). ω is the flow
//!   *into* the `shaft` port: draw the bond from the drive to the pump (`drive -> pump.shaft`),
//!   its effort is the torque the drive applies. With D > 0 and ω > 0 it delivers Q = D·ω
//!   from `a` to `b` against Δp = P_b − P_a.
//! * Motor: `a` is the inlet (high), `b` the outlet (low). ω is the flow *out of* `shaft`:
//!   draw the bond from the motor to its load (`motor.shaft -> load`), its effort is the
//!   torque the motor delivers. With D > 0, oil flowing from `a` to `b` turns it at ω > 0.
//!
//! A motor is a pump with its ports named the other way round: the law is the same machine,
//! and all four quadrants follow from the signs of ω and Δp (a pump turned backwards sucks
//! through `b`; a pump with P_a > P_b is driven by the oil, i.e. motoring; a motor dragged
//! by its load pumps). The power in is
//!
//! ```text
//! P_a·Q − P_b·Q + T·f_in,shaft = C_l·Δ² + T_f(ω)·ω ≥ 0
//! ```
//!
//! exactly the dissipation of the two losses; with C_l = 0 and no friction the machine
//! conserves power. Efficiencies in the pumping quadrant (ω, Δp = P_b − P_a > 0) and in the
//! motoring quadrant (ω, Δp = P_a − P_b > 0), with D > 0:
//!
//! ```text
//! pump:  η_v = Q/(D·ω) = 1 − C_l·Δp/(D·ω)      η_hm = D·Δp/T = D·Δp/(D·Δp + T_f(ω))
//! motor: η_v = D·ω/Q = D·ω/(D·ω + C_l·Δp)      η_hm = T/(D·Δp) = 1 − T_f(ω)/(D·Δp)
//! ```
//!
//! **Causality** (fixed): `a` and `b` receive the pressure (a chamber, a 0-junction with a
//! chamber, a tank `Se`) and set their flow; `shaft` receives the speed (an inertia on its
//! 1-junction, or an `Sf`) and sets the torque.
//!
//! **Pump driven at a set speed.** [`Machine::pump_at_speed`] (`speed` in a model file)
//! has no shaft port: ω is a (possibly modulated) parameter, the pump is a flow source
//! `Q = D·ω − C_l·Δp` with ports `a`, `b`, and it publishes the torque the drive must
//! apply as the signal `torque` (N·m), so the drive power is `torque·ω`.

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params, Range};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage,
};

use crate::friction::{law_of, FrictionLaw};

/// Which convention the shaft follows: a pump takes power in at its shaft, a motor gives it out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// ω = flow into `shaft`; `a` inlet (low), `b` outlet (high).
    Pump,
    /// ω = flow out of `shaft`; `a` inlet (high), `b` outlet (low).
    Motor,
}

/// A displacement machine (see the module doc for the law and the signs).
///
/// * `d_max` — displacement at full stroke, m³/rad, > 0 (a catalogue's V in cm³/rev is
///   D = V·1e-6/(2π) m³/rad).
/// * `fraction` — ε, the displacement fraction (modulated for a variable machine), clamped
///   to [−1, 1]; a constant must lie in [−1, 1]. Default 1 (fixed displacement).
/// * `c_l` — laminar leakage coefficient, m³/(s·Pa), ≥ 0 (default 0).
/// * `friction` — the friction torque T_f(ω) (default none).
/// * `speed` — pump only: the shaft speed ω (rad/s), which removes the shaft port.
#[derive(Debug)]
pub struct Machine {
    role: Role,
    d_max: f64,
    fraction: Param,
    c_l: f64,
    friction: FrictionLaw,
    speed: Option<Param>,
}

impl Machine {
    /// A pump or motor with a shaft port, fixed displacement `d_max` (ε = 1), no losses.
    pub fn new(role: Role, d_max: f64) -> Result<Self, ParamError> {
        ParamError::positive("displacement", d_max)?;
        Ok(Self {
            role,
            d_max,
            fraction: Param::Const(1.0),
            c_l: 0.0,
            friction: FrictionLaw::none(),
            speed: None,
        })
    }

    /// A pump driven at the shaft speed `speed` (rad/s): no shaft port, a flow source.
    pub fn pump_at_speed(d_max: f64, speed: impl Into<Param>) -> Result<Self, ParamError> {
        let speed = speed.into();
        if let Some(w) = speed.constant() {
            ParamError::finite("speed", w)?;
        }
        let mut m = Self::new(Role::Pump, d_max)?;
        m.speed = Some(speed);
        Ok(m)
    }

    /// Set the displacement fraction ε (variable displacement).
    pub fn with_fraction(mut self, fraction: impl Into<Param>) -> Result<Self, ParamError> {
        let fraction = fraction.into();
        if let Some(e) = fraction.constant() {
            if !(-1.0..=1.0).contains(&e) {
                return Err(ParamError::OutOfRange {
                    param: "fraction".into(),
                    value: e,
                    requirement: "within [-1, 1]",
                });
            }
        }
        self.fraction = fraction;
        Ok(self)
    }

    /// Set the laminar leakage coefficient C_l (m³/(s·Pa)).
    pub fn with_leakage(mut self, c_l: f64) -> Result<Self, ParamError> {
        self.c_l = ParamError::non_negative("c_l", c_l)?;
        Ok(self)
    }

    /// Set the friction torque law T_f(ω).
    #[must_use]
    pub fn with_friction(mut self, friction: FrictionLaw) -> Self {
        self.friction = friction;
        self
    }

    /// The laminar leakage coefficient C_l, m³/(s·Pa).
    #[must_use]
    pub fn leakage(&self) -> f64 {
        self.c_l
    }

    /// The friction torque law T_f(ω).
    #[must_use]
    pub fn friction(&self) -> &FrictionLaw {
        &self.friction
    }

    /// Whether the shaft is a port (false for a pump driven at a set speed).
    #[must_use]
    pub fn has_shaft(&self) -> bool {
        self.speed.is_none()
    }

    /// Shaft sign r: ω = r·f_in,shaft (pump +1, motor −1).
    fn r(&self) -> f64 {
        match self.role {
            Role::Pump => 1.0,
            Role::Motor => -1.0,
        }
    }

    /// Flow from `a` to `b` (m³/s) at displacement `d` (m³/rad), speed ω, Δ = P_a − P_b.
    #[must_use]
    pub fn flow(&self, d: f64, omega: f64, delta: f64) -> f64 {
        d * omega + self.c_l * delta
    }

    /// Shaft torque (N·m) in the role's convention: applied by the drive (pump), delivered
    /// to the load (motor).
    #[must_use]
    pub fn torque(&self, d: f64, omega: f64, delta: f64) -> f64 {
        self.r() * (self.friction.force(omega) - d * delta)
    }

    /// The clamped fraction and its slope (0 where the clamp is active).
    fn epsilon(&self, io: &Io<'_>) -> (f64, f64) {
        let e = self.fraction.value(io, 0);
        if e > 1.0 {
            (1.0, 0.0)
        } else if e < -1.0 {
            (-1.0, 0.0)
        } else {
            (e, 1.0)
        }
    }

    /// ω now: the speed parameter, or r·f_in at the shaft.
    fn omega(&self, io: &Io<'_>) -> f64 {
        match &self.speed {
            Some(w) => w.value(io, self.fraction.n_inputs()),
            None => self.r() * io.f_in(2, 0),
        }
    }

    fn n_inputs(&self) -> usize {
        self.fraction.n_inputs() + self.speed.as_ref().map_or(0, Param::n_inputs)
    }
}

impl Element for Machine {
    fn kind(&self) -> &str {
        match self.role {
            Role::Pump => "hydraulics.pump",
            Role::Motor => "hydraulics.motor",
        }
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
        // Driven at a set speed: the drive's power r·T·ω (T in the role's convention).
        if self.has_shaft() {
            return None;
        }
        let d = self.d_max * self.epsilon(io).0;
        let omega = self.omega(io);
        let delta = io.e(0, 0) - io.e(1, 0);
        Some(self.r() * self.torque(d, omega, delta) * omega)
    }
    fn ports(&self) -> Ports {
        let mut p = vec![PortSpec::new("a", 1), PortSpec::new("b", 1)];
        if self.has_shaft() {
            p.push(PortSpec::new("shaft", 1));
        }
        Ports::Fixed(p)
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        use PortCausality::{EffortOut, FlowOut};
        if self.has_shaft() {
            CausalRule::Fixed(vec![FlowOut, FlowOut, EffortOut])
        } else {
            CausalRule::Fixed(vec![FlowOut, FlowOut])
        }
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        let mut s = self.fraction.signal_inputs();
        if let Some(w) = &self.speed {
            s.extend(w.signal_inputs());
        }
        s
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        if self.has_shaft() {
            Vec::new()
        } else {
            vec![SignalSpec::scalar("torque")]
        }
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let mut reads = vec![Slot::Effort(0), Slot::Effort(1)];
        if self.has_shaft() {
            reads.push(Slot::Flow(2));
        }
        reads.extend((0..self.n_inputs()).map(Slot::Input));
        let torque = if self.has_shaft() {
            Slot::Effort(2)
        } else {
            Slot::Output(0)
        };
        vec![
            Stage {
                writes: vec![Slot::Flow(0), Slot::Flow(1)],
                reads: reads.clone(),
            },
            Stage {
                writes: vec![torque],
                reads,
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let d = self.d_max * self.epsilon(io).0;
        let omega = self.omega(io);
        let delta = io.e(0, 0) - io.e(1, 0);
        if stage == 0 {
            let q = self.flow(d, omega, delta);
            io.set_f_in(0, 0, q);
            io.set_f_in(1, 0, -q);
        } else if self.has_shaft() {
            io.set_e(2, 0, self.torque(d, omega, delta));
        } else {
            io.set_y(0, 0, self.torque(d, omega, delta));
        }
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let (eps, deps) = self.epsilon(io);
        let d = self.d_max * eps;
        let omega = self.omega(io);
        let delta = io.e(0, 0) - io.e(1, 0);
        let r = self.r();
        // (∂y/∂Δ, ∂y/∂ω, ∂y/∂D) for y = Q (stage 0) or the torque (stage 1)
        let (rows, dy_ddelta, dy_domega, dy_dd): (&[(Slot, f64)], f64, f64, f64) = if stage == 0 {
            (
                &[(Slot::Flow(0), 1.0), (Slot::Flow(1), -1.0)],
                self.c_l,
                d,
                omega,
            )
        } else {
            let slot = if self.has_shaft() {
                Slot::Effort(2)
            } else {
                Slot::Output(0)
            };
            (
                &[(slot, 1.0)][..],
                -r * d,
                r * self.friction.slope(omega),
                -r * delta,
            )
        };
        let nf = self.fraction.n_inputs();
        for &(slot, s) in rows {
            let row = jac.row(slot, 0);
            jac.set(row, jac.effort_col(0, 0), s * dy_ddelta);
            jac.set(row, jac.effort_col(1, 0), -s * dy_ddelta);
            match &self.speed {
                None => jac.set(row, jac.flow_col(2, 0), s * dy_domega * r),
                Some(w) => w.partials(io, nf, |i, dw| {
                    jac.set(row, jac.input_col(nf + i, 0), s * dy_domega * dw);
                }),
            }
            self.fraction.partials(io, 0, |i, de| {
                jac.set(row, jac.input_col(i, 0), s * dy_dd * self.d_max * deps * de);
            });
        }
        true
    }
}

pub(crate) const DISPLACEMENT: ParamDecl = ParamDecl::number(
    "displacement",
    "m³/rad",
    "displacement D_max at full stroke (\"40 cc/rev\" is read as 40e-6/(2π))",
)
.positive();
const FRACTION: ParamDecl = ParamDecl::modulated(
    "fraction",
    "1",
    "displacement fraction ε, D = ε·D_max (modulated: a variable machine; clamped to [−1, 1])",
)
.range(Range::closed(-1.0, 1.0))
.default(1.0);
pub(crate) const C_L: ParamDecl = ParamDecl::number(
    "c_l",
    "m³/(s·Pa)",
    "laminar leakage coefficient, Q_leak = C_l·Δp",
)
.non_negative()
.default(0.0);
pub(crate) const T_C: ParamDecl = ParamDecl::number("t_c", "N·m", "Coulomb friction torque")
    .non_negative()
    .default(0.0);
pub(crate) const T_S: ParamDecl = ParamDecl::number("t_s", "N·m", "breakaway friction torque")
    .non_negative()
    .optional("t_c: no Stribeck peak");
pub(crate) const OMEGA_S: ParamDecl = ParamDecl::number("omega_s", "rad/s", "Stribeck speed")
    .positive()
    .optional("needed with t_s");
pub(crate) const OMEGA_TANH: ParamDecl = ParamDecl::number(
    "omega_tanh",
    "rad/s",
    "regularisation speed of the Coulomb torque's sign(ω)",
)
.positive()
.default(0.1);
pub(crate) const B: ParamDecl = ParamDecl::number("b", "N·m·s/rad", "viscous friction coefficient")
    .non_negative()
    .default(0.0);

/// The set shaft speed of a pump (shared with `hydraulics.ls_pump`).
pub(crate) const SPEED: ParamDecl = ParamDecl::modulated(
    "speed",
    "rad/s",
    "shaft speed ω (\"1500 rpm\", or a signal): the pump is a flow source with no shaft port",
)
.optional("a shaft port, driven by the model");

/// The machine of `role` from a model's parameters (`speed` only for the pump).
fn build(p: &dyn Params, role: Role) -> Result<Machine, BuildError> {
    let d = p.number("displacement")?;
    let speed = if role == Role::Pump && p.has("speed") {
        Some(p.modulated("speed")?)
    } else {
        None
    };
    let m = match speed {
        Some(w) => Machine::pump_at_speed(d, w)?,
        None => Machine::new(role, d)?,
    };
    let friction = law_of(p, ["t_c", "t_s", "omega_s", "omega_tanh", "b"])?;
    Ok(m.with_fraction(p.modulated("fraction")?)?
        .with_leakage(p.number("c_l")?)?
        .with_friction(friction))
}

/// Kind `hydraulics.pump`.
pub const PUMP: KindDecl = KindDecl::element(
    "hydraulics.pump",
    "displacement pump a → b: Q = D·ω − C_l·Δp, T = D·Δp + T_f(ω); port shaft (ω in), or `speed` (no shaft; publishes torque)",
    &[
        DISPLACEMENT,
        FRACTION,
        C_L,
        T_C,
        T_S,
        OMEGA_S,
        OMEGA_TANH,
        B,
        SPEED,
    ],
    |p| Ok(Box::new(build(p, Role::Pump)?)),
)
.example("displacement = 6.4e-6, c_l = 1e-12, t_c = 1.5, b = 3e-3");

/// Kind `hydraulics.motor`.
pub const MOTOR: KindDecl = KindDecl::element(
    "hydraulics.motor",
    "displacement motor a → b: Q = D·ω + C_l·Δp, T = D·Δp − T_f(ω) delivered at shaft (ω out)",
    &[
        DISPLACEMENT,
        FRACTION,
        C_L,
        T_C,
        T_S,
        OMEGA_S,
        OMEGA_TANH,
        B,
    ],
    |p| Ok(Box::new(build(p, Role::Motor)?)),
)
.example("displacement = 8e-6, c_l = 1.5e-12, t_c = 2, b = 5e-3");

#[cfg(test)]
mod tests;
