//! Winch `mechanical.winch`: a drum paying out or hauling in a wire.
//!
//! Two ports, power in positive: `shaft` (effort the motor's torque T [N·m], flow the
//! shaft speed ω_m [rad/s]) and `wire` (effort the wire tension F [N], flow the pay-out
//! speed v [m/s], positive as wire leaves the drum). A gear of ratio n (motor turns per
//! drum turn) joins the shaft to the drum: ω_m = n·ω. The drum (radius r, inertia J about
//! its axis, all rotating parts referred to it) is an I-field with two ports:
//!
//! - J·dω/dt = n·T + r·F − b·ω − T_b·tanh(ω/ω_b)      (momentum p = J·ω is the state)
//! - ω_m = n·ω,  v = r·ω                              (flows out: integral causality)
//! - dL/dt = v = r·ω                                  (paid-out length L, a state)
//!
//! Power: T·ω_m + F·v = (n·T + r·F)·ω, what the drum's torque balance absorbs, so the
//! element is a lossy storage: kinetic energy p²/2J, losses b·ω² + T_b·ω·tanh(ω/ω_b).
//! The brake torque T_b may be a signal expression (a brake engaged by a controller); its
//! Coulomb law is regularised by tanh with speed scale ω_b (`brake_speed`, default
//! 0.01 rad/s): a held drum creeps at ω ≈ ω_b·atanh(torque/T_b) instead of sticking. A
//! load on the wire port needs compliance between it and the drum (both are inertias):
//! the wire's spring, or the arm's wire payload.
//! Outputs: `length` (L), `omega` (ω), `speed` (v).

use bondgraph::element::{CausalRule, Element, Io, Param, PortSpec, Ports, SignalSpec, Slot, Stage, StateSpec};
use bondgraph::energy::EnergyRole;
use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::{LocalJacobian, ParamError, PortCausality};

/// A winch drum (see the module documentation).
#[derive(Debug)]
pub struct Winch {
    radius: f64,
    inertia: f64,
    ratio: f64,
    damping: f64,
    brake: Param,
    brake_speed: f64,
    length0: f64,
}

impl Winch {
    /// A drum of `radius` [m] and `inertia` [kg·m²] behind a gear of `ratio`, viscous
    /// `damping` [N·m·s/rad], brake torque `brake` [N·m] regularised over `brake_speed`
    /// [rad/s], with `length0` [m] of wire paid out at the start (the drum at rest).
    ///
    /// # Errors
    /// A radius, inertia, ratio or brake speed not positive, a damping negative, a length
    /// not finite.
    pub fn new(
        radius: f64,
        inertia: f64,
        ratio: f64,
        damping: f64,
        brake: impl Into<Param>,
        brake_speed: f64,
        length0: f64,
    ) -> Result<Self, ParamError> {
        ParamError::positive("r", radius)?;
        ParamError::positive("J", inertia)?;
        ParamError::positive("ratio", ratio)?;
        ParamError::positive("brake_speed", brake_speed)?;
        ParamError::finite("b", damping)?;
        ParamError::finite("length", length0)?;
        if damping < 0.0 {
            return Err(ParamError::shape("b", format!("b = {damping} must be ≥ 0")));
        }
        Ok(Self {
            radius,
            inertia,
            ratio,
            damping,
            brake: brake.into(),
            brake_speed,
            length0,
        })
    }
    fn omega(&self, io: &Io<'_>) -> f64 {
        io.states()[0] / self.inertia
    }
}

impl Element for Winch {
    fn kind(&self) -> &str {
        "mechanical.winch"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("shaft", 1), PortSpec::new("wire", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![PortCausality::FlowOut, PortCausality::FlowOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![
            StateSpec::new("p", 0.0),
            StateSpec::new("length", self.length0),
        ]
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.brake.signal_inputs()
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![
            SignalSpec::scalar("length"),
            SignalSpec::scalar("omega"),
            SignalSpec::scalar("speed"),
        ]
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        Stage::from_states(causality, 0, 3)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let w = self.omega(io);
        let length = io.states()[1];
        io.set_f_in(0, 0, self.ratio * w);
        io.set_f_in(1, 0, self.radius * w);
        io.set_y(0, 0, length);
        io.set_y(1, 0, w);
        io.set_y(2, 0, self.radius * w);
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        let w = self.omega(io);
        let tb = self.brake.value(io, 0);
        dx[0] = self.ratio * io.e(0, 0) + self.radius * io.e(1, 0)
            - self.damping * w
            - tb * (w / self.brake_speed).tanh();
        dx[1] = self.radius * w;
    }
    fn stage_partials(&self, _: usize, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let j = self.inertia;
        let (cp, cl) = (jac.state_col(0), jac.state_col(1));
        jac.set(jac.row(Slot::Flow(0), 0), cp, self.ratio / j);
        jac.set(jac.row(Slot::Flow(1), 0), cp, self.radius / j);
        jac.set(jac.row(Slot::Output(0), 0), cl, 1.0);
        jac.set(jac.row(Slot::Output(1), 0), cp, 1.0 / j);
        jac.set(jac.row(Slot::Output(2), 0), cp, self.radius / j);
        true
    }
    fn derivative_partials(&self, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let w = self.omega(io);
        let tb = self.brake.value(io, 0);
        let th = (w / self.brake_speed).tanh();
        let (r0, r1) = (jac.derivative_row(0), jac.derivative_row(1));
        jac.set(r0, jac.effort_col(0, 0), self.ratio);
        jac.set(r0, jac.effort_col(1, 0), self.radius);
        let dw = -self.damping - tb * (1.0 - th * th) / self.brake_speed;
        jac.set(r0, jac.state_col(0), dw / self.inertia);
        self.brake
            .partials(io, 0, |k, d| jac.set(r0, jac.input_col(k, 0), -d * th));
        jac.set(r1, jac.state_col(0), self.radius / self.inertia);
        true
    }
    fn stored_energy(&self, x: &[f64]) -> Option<f64> {
        Some(0.5 * x[0] * x[0] / self.inertia)
    }
    fn energy_role(&self, _: usize) -> EnergyRole {
        EnergyRole::LossyStorage
    }
}

/// Kind `mechanical.winch`.
pub const KIND: KindDecl = KindDecl::element(
    "mechanical.winch",
    "winch drum: shaft port (torque, speed) through a gear, wire port (tension, pay-out speed), paid-out length as a state",
    &[
        ParamDecl::number("r", "m", "drum radius (to the wire's centre line)").positive(),
        ParamDecl::number("J", "kg*m^2", "inertia of the drum and everything turning with it, about the drum axis").positive(),
        ParamDecl::number("ratio", "", "gear ratio n: motor turns per drum turn").default(1.0).positive(),
        ParamDecl::number("b", "N*m*s/rad", "viscous damping of the drum").default(0.0).non_negative(),
        ParamDecl::modulated("brake", "N*m", "brake torque T_b (may read signals)").default(0.0),
        ParamDecl::number("brake_speed", "rad/s", "speed scale of the brake's tanh regularisation").default(0.01).positive(),
        ParamDecl::number("length", "m", "wire paid out at the start").default(0.0),
    ],
    |p| {
        Ok(Box::new(Winch::new(
            p.number("r")?,
            p.number("J")?,
            p.number("ratio")?,
            p.number("b")?,
            p.modulated("brake")?,
            p.number("brake_speed")?,
            p.number("length")?,
        )?))
    },
)
.example("r = 0.5, J = 50.0");

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;
    use bondgraph::{
        assign_causality, check_partials, simulate, BondGraph, Capacitor, EffortSource, Inertia,
        OneJunction, Resistor, Settings, StateEquations, ZeroJunction,
    };

    const G: f64 = 9.81;

    /// A motor torque T on the shaft, a mass m on the wire through a stiff rope (spring k,
    /// damper c in parallel), gravity m·g: returns (paid-out length, pay-out speed) at
    /// `t_end` (r = 0.5 m, J = 50 kg·m², as every test here uses).
    fn hang(winch: Winch, torque: f64, m: f64, t_end: f64) -> (f64, f64) {
        let (k, c) = (1e7, 2.0 * 0.7 * (1e7 * m).sqrt());
        let mut g = BondGraph::new();
        g.add("motor", EffortSource::new(torque)).unwrap();
        g.add("winch", winch).unwrap();
        g.add("rope_end", ZeroJunction).unwrap();
        g.add("stretch", OneJunction).unwrap();
        g.add("spring", Capacitor::new(1.0 / k, m * G / k).unwrap()).unwrap();
        g.add("damper", Resistor::new(c).unwrap()).unwrap();
        g.add("load", OneJunction).unwrap();
        g.add("mass", Inertia::new(m, 0.0).unwrap()).unwrap();
        g.add("gravity", EffortSource::new(m * G)).unwrap();
        for (a, b) in [
            ("motor", "winch"),
            ("load", "rope_end"),
            ("rope_end", "winch"),
            ("rope_end", "stretch"),
            ("stretch", "spring"),
            ("stretch", "damper"),
            ("gravity", "load"),
            ("load", "mass"),
        ] {
            g.connect_names(a, b).unwrap();
        }
        let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        let x0 = eqs.initial_state();
        let settings = Settings {
            t_end,
            rtol: 1e-9,
            atol: 1e-9,
            ..Settings::default()
        };
        let run = simulate(&mut eqs, &x0, &settings, &[], vec![]);
        assert!(run.error.is_none(), "{:?}", run.error);
        let names: Vec<String> = eqs.states().iter().map(|s| s.name.clone()).collect();
        let at = |n: &str| names.iter().position(|s| s == n).unwrap();
        let p = run.x_final[at("winch.p")];
        (run.x_final[at("winch.length")], 0.5 * p / 50.0)
    }

    /// The issue's "done when": a winch at constant torque against a hanging mass reaches
    /// the closed-form steady pay-out: with the load's weight on the wire (F = m·g, no
    /// acceleration), 0 = n·T + r·m·g − b·ω, so v = r·(n·T + r·m·g)/b.
    #[test]
    fn constant_torque_against_a_hanging_mass_reaches_the_steady_pay_out() {
        let (r, j, n, b, m, torque) = (0.5, 50.0, 1.0, 2000.0, 1000.0, -4000.0);
        let winch = Winch::new(r, j, n, b, 0.0, 0.01, 10.0).unwrap();
        // time constant (J + m·r²)/b = 0.15 s: 20 s is 130 of them
        let (_, v) = hang(winch, torque, m, 20.0);
        let want = r * (n * torque + r * m * G) / b;
        assert!((v / want - 1.0).abs() < 1e-6, "v = {v}, closed form {want}");
    }

    /// Without damping the drum and the load accelerate together:
    /// (J + m·r²)·α = n·T + r·m·g, and L(t) = L0 + r·α·t²/2 (the stiff rope's stretch
    /// changes by m·r·α/k, 1e-6 m here).
    #[test]
    fn without_damping_the_load_accelerates_by_the_closed_form() {
        let (r, j, m, torque) = (0.5, 50.0, 1000.0, -4000.0);
        let winch = Winch::new(r, j, 1.0, 0.0, 0.0, 0.01, 10.0).unwrap();
        let t = 2.0;
        let (length, _) = hang(winch, torque, m, t);
        let alpha = (torque + r * m * G) / (j + m * r * r);
        let want = 10.0 + 0.5 * r * alpha * t * t;
        assert!((length - want).abs() < 1e-4 * (want - 10.0), "L = {length}, closed form {want}");
    }

    #[test]
    fn a_brake_holds_the_load_creeping_at_the_regularised_speed() {
        // brake 6000 N·m against the net 905 N·m: ω = ω_b·atanh(905/6000)
        let (r, m, torque) = (0.5, 1000.0, -4000.0);
        let winch = Winch::new(r, 50.0, 1.0, 0.0, 6000.0, 0.01, 10.0).unwrap();
        let (_, v) = hang(winch, torque, m, 5.0);
        let want = r * 0.01 * ((torque + r * m * G) / 6000.0f64).atanh();
        assert!((v / want - 1.0).abs() < 1e-5, "v = {v}, closed form {want}");
    }

    #[test]
    fn partials_match_central_differences_and_bad_numbers_are_refused() {
        let brake = Param::modulated(vec!["u".into()], |_, u| 100.0 * u[0]);
        let w = Winch::new(0.4, 20.0, 3.0, 15.0, brake, 0.05, 2.0).unwrap();
        // T, F, ω_m, v, u, p, L
        let point = [300.0, 2000.0, 0.0, 0.0, 0.8, 1.5, 2.0];
        let ports = [(1, 1.0, PortCausality::FlowOut), (1, 1.0, PortCausality::FlowOut)];
        assert_eq!(check_partials(&w, &ports, &point), Ok(2));
        assert!(Winch::new(0.0, 1.0, 1.0, 0.0, 0.0, 0.01, 0.0).is_err());
        assert!(Winch::new(0.5, 1.0, 1.0, -1.0, 0.0, 0.01, 0.0).is_err());
    }
}
