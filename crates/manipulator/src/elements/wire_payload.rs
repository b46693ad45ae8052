//! The payload on an elastic wire of varying length, with an optional landing on a moving
//! deck (docs/offshore.md).
//!
//! The payload is a point mass m with its own two degrees of freedom, position r and
//! momentum p in the inertial frame (states `x, y, px, py`), hanging from the end of the
//! arm's last chord, the tip, by a wire of paid-out length L (a parameter, or with a winch
//! the state `L`, integrating the pay-out speed the winch port receives). With ê the unit
//! vector from the tip to the payload, the stretch and its rate are
//!
//! ```text
//! s = |r − r_tip| − L        ṡ = ê·(ṙ − ṙ_tip) − L̇
//! T = max₁( k σ(s) + c σ'(s) ṡ )        k = EA / L,  c = τ k
//! ```
//!
//! where τ is the wire's Kelvin–Voigt time constant (`damping`, s), σ the C¹ ramp of the
//! stretch (σ = 0 for s ≤ 0, s²/2δ for 0 < s < δ, s − δ/2 beyond; δ = `slack_band`, 1 µm by
//! default) and max₁ the same C¹ ramp of the force over the band k δ. The wire is exactly
//! slack (T = 0, not a small number) whenever s ≤ 0, and the tension is continuous with a
//! continuous derivative everywhere: the stiff solver's Newton iteration sees no jump, and
//! its error control shortens the steps over the take-up (a smooth law, not events: no root
//! finding, and the Jacobian stays well defined). The static error of the smoothing is δ/2
//! of stretch.
//!
//! ```text
//! ṙ = p / m      ṗ = −m g ŷ − T ê + F_contact      L̇ = pay-out speed (with a winch)
//! ```
//!
//! On the arm the wire pulls the tip with T ê: the effort on port `1` (n) is `−Jᵀ R(−θ) T ê`
//! (J the tip's velocity Jacobian, base axes), like the C-field's `−G`. Port `wire` (with a
//! winch): effort T (N), flow the pay-out speed L̇ (m/s) out of this element, so that the
//! winch receives the power T L̇.
//!
//! # Landing
//! A deck at height h(t) (any motion of time, inertial) under the payload: with the
//! penetration δ = h − y and its rate δ̇ = ḣ − ẏ, a Hunt–Crossley contact
//! `F_n = max(0, k_c δⁿ + λ δⁿ δ̇)` for δ > 0 (no pull: it cannot hold the payload down),
//! and regularised Coulomb friction `F_t = −μ F_n tanh(ẋ / v_ε)` against a deck that does
//! not move sideways. For n > 1 the force starts from zero with zero slope.

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{
    CausalRule, Element, Io, Motion, ParamError, PortCausality, PortSpec, Ports, SignalSpec, Slot,
    Stage, StateSpec,
};
use nalgebra::Vector2;

use crate::arm::{Frames, PlanarArm, Station};
use crate::base::{Base, BaseState};

/// The landing surface and its contact law.
#[derive(Clone, Debug)]
pub struct Landing {
    /// Height of the deck (m, inertial), a function of time.
    pub height: Motion,
    /// Contact stiffness k_c (N/mⁿ).
    pub stiffness: f64,
    /// Exponent n (1.5 for Hertz).
    pub exponent: f64,
    /// Hunt–Crossley damping λ (N·s/mⁿ⁺¹).
    pub damping: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    /// The sliding speed over which friction builds up (m/s).
    pub slip_speed: f64,
}

/// The payload on its wire.
#[derive(Clone, Debug)]
pub struct WireSpec {
    /// Payload mass (kg).
    pub mass: f64,
    /// Axial stiffness EA of the wire (N).
    pub ea: f64,
    /// Kelvin–Voigt time constant τ (s): damping c = τ EA / L.
    pub damping: f64,
    /// Paid-out length at the start (m).
    pub length: f64,
    /// Whether a winch pays it out (port `wire`, state L); else L is fixed.
    pub winch: bool,
    /// The smoothing band δ of the slack/taut transition (m of stretch).
    pub slack_band: f64,
    /// Start hanging at rest with the static stretch (else unstretched).
    pub start_stretched: bool,
    /// The landing, if any.
    pub landing: Option<Landing>,
}

/// Outputs, in order.
pub const PAYLOAD_OUTPUTS: [&str; 14] = [
    "x", "y", "vx", "vy", "T", "L", "stretch", "Fx", "Fy", "contact", "friction", "deck", "tip_y",
    "tip_vy",
];
const OUT_FX: usize = 7;

/// The payload element (see the module documentation).
#[derive(Debug)]
pub struct WirePayload {
    arm: Arc<PlanarArm>,
    tip: Station,
    base: Base,
    gravity: f64,
    spec: WireSpec,
    q_signal: String,
    x0: [f64; 4],
    ws: RefCell<(Frames, Vec<f64>)>,
}

/// Everything at one state.
#[derive(Clone, Copy, Debug, Default)]
struct At {
    tension: f64,
    stretch: f64,
    /// Unit vector tip → payload, inertial.
    e: Vector2<f64>,
    /// Force on the tip, base axes.
    on_tip: Vector2<f64>,
    contact: f64,
    friction: f64,
    deck: f64,
    /// The tip's height and vertical speed, inertial.
    tip: [f64; 2],
}

/// The C¹ ramp: 0 for x ≤ 0, x²/2δ below δ, x − δ/2 beyond; and its slope.
#[inline]
fn ramp(x: f64, band: f64) -> (f64, f64) {
    if x <= 0.0 {
        (0.0, 0.0)
    } else if x < band {
        (x * x / (2.0 * band), x / band)
    } else {
        (x - 0.5 * band, 1.0)
    }
}

impl WirePayload {
    /// The payload `spec` hanging from the end of `arm`'s last chord, the arm at `q0`,
    /// reading its configuration from `q_signal`, on `base` under `gravity`.
    pub fn new(
        arm: Arc<PlanarArm>,
        spec: WireSpec,
        base: Base,
        gravity: f64,
        q_signal: &str,
        q0: &[f64],
    ) -> Result<Self, ParamError> {
        for (name, v) in [
            ("payload.mass", spec.mass),
            ("payload.EA", spec.ea),
            ("payload.length", spec.length),
            ("payload.slack_band", spec.slack_band),
        ] {
            ParamError::positive(name, v)?;
        }
        ParamError::finite("payload.damping", spec.damping)?;
        if spec.damping < 0.0 {
            return Err(ParamError::invalid("payload.damping", spec.damping, ">= 0"));
        }
        if let Some(l) = &spec.landing {
            ParamError::positive("landing.k", l.stiffness)?;
            ParamError::positive("landing.n", l.exponent)?;
            ParamError::positive("landing.slip_speed", l.slip_speed)?;
            for (name, v) in [("landing.lambda", l.damping), ("landing.mu", l.friction)] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(ParamError::invalid(name, v, ">= 0"));
                }
            }
        }
        let last = arm.n_links() - 1;
        let tip = arm.station(last, arm.links()[last].length())?;
        let tip0 = arm.pose(q0).position(&tip);
        let b0 = base.at(0.0);
        let hang = if spec.start_stretched {
            spec.length * (1.0 + spec.mass * gravity / spec.ea)
        } else {
            spec.length
        };
        let r0 = b0.to_inertial(&tip0) + Vector2::new(0.0, -hang);
        let x0 = [r0.x, r0.y, spec.mass * b0.x[1], spec.mass * b0.y[1]];
        Ok(Self {
            ws: RefCell::new((arm.frames(), vec![0.0; arm.n()])),
            arm,
            tip,
            base,
            gravity,
            spec,
            q_signal: q_signal.to_owned(),
            x0,
        })
    }

    /// The tension, contact and forces at time t, states x, arm coordinates q and speeds
    /// `u(k)`, pay-out speed `ldot`.
    fn at(&self, t: f64, x: &[f64], q: &[f64], u: impl Fn(usize) -> f64, ldot: f64) -> At {
        let m = self.spec.mass;
        let (r, v) = (Vector2::new(x[0], x[1]), Vector2::new(x[2], x[3]) / m);
        let length = if self.spec.winch {
            x[4]
        } else {
            self.spec.length
        };
        let b: BaseState = self.base.at(t);
        let mut ws = self.ws.borrow_mut();
        let pose = self.arm.pose_in(q, &mut ws.0);
        let tip = pose.position(&self.tip);
        let mut v_rel = Vector2::zeros();
        pose.point_jacobian(&self.tip, |k, col| v_rel += col * u(k));
        let (s, c) = b.roll[0].sin_cos();
        let turn = |w: Vector2<f64>| Vector2::new(c * w.x - s * w.y, s * w.x + c * w.y);
        let tip_i = b.to_inertial(&tip);
        let arm_i = turn(tip);
        let v_tip = Vector2::new(b.x[1], b.y[1])
            + b.roll[1] * Vector2::new(-arm_i.y, arm_i.x)
            + turn(v_rel);
        let d = r - tip_i;
        let dist = d.norm();
        let e = if dist > 0.0 {
            d / dist
        } else {
            Vector2::new(0.0, -1.0)
        };
        let stretch = dist - length;
        let rate = e.dot(&(v - v_tip)) - ldot;
        let k = self.spec.ea / length;
        let band = self.spec.slack_band;
        let (sig, dsig) = ramp(stretch, band);
        let (tension, _) = ramp(k * sig + self.spec.damping * k * dsig * rate, k * band);
        let f_tip = tension * e;
        let on_tip = Vector2::new(c * f_tip.x + s * f_tip.y, -s * f_tip.x + c * f_tip.y);
        let (mut contact, mut friction, mut deck) = (0.0, 0.0, f64::NAN);
        if let Some(l) = &self.spec.landing {
            let [h, hd, _] = l.height.eval(t);
            deck = h;
            let pen = h - r.y;
            if pen > 0.0 {
                let dn = pen.powf(l.exponent);
                contact = (l.stiffness * dn + l.damping * dn * (hd - v.y)).max(0.0);
                friction = -l.friction * contact * (v.x / l.slip_speed).tanh();
            }
        }
        At {
            tension,
            stretch,
            e,
            on_tip,
            contact,
            friction,
            deck,
            tip: [tip_i.y, v_tip.y],
        }
    }

    fn read_at(&self, io: &Io<'_>) -> At {
        let ldot = if self.spec.winch { -io.f_in(1, 0) } else { 0.0 };
        self.at(io.time(), io.states(), io.input(0), |k| io.f_in(0, k), ldot)
    }
}

impl Element for WirePayload {
    fn kind(&self) -> &str {
        "manipulator.wire_payload"
    }
    fn ports(&self) -> Ports {
        let mut p = vec![PortSpec::new("1", self.arm.n())];
        if self.spec.winch {
            p.push(PortSpec::new("wire", 1));
        }
        Ports::Fixed(p)
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        let n = 1 + usize::from(self.spec.winch);
        CausalRule::Fixed(vec![PortCausality::EffortOut; n])
    }
    /// The payload is an open subsystem: gravity and a moving deck do work on it, it stores
    /// kinetic and strain energy and its wire and contact dissipate. The energy audit counts
    /// it at the graph's boundary (its net port power as supplied), not its inner balance.
    /// The stretch is the small difference of two long distances (tip to payload, paid-out
    /// length) times a stiff EA/L: forward differences at √ε keep too few digits of it.
    fn central_differences(&self) -> bool {
        true
    }
    fn energy_role(&self, _: usize) -> bondgraph::EnergyRole {
        bondgraph::EnergyRole::Source
    }
    fn states(&self) -> Vec<StateSpec> {
        let mut s: Vec<StateSpec> = ["x", "y", "px", "py"]
            .iter()
            .zip(self.x0)
            .map(|(n, v)| StateSpec::new(n, v))
            .collect();
        if self.spec.winch {
            s.push(StateSpec::new("L", self.spec.length));
        }
        s
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec {
            name: self.q_signal.clone(),
            dim: self.arm.n(),
        }]
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        PAYLOAD_OUTPUTS
            .iter()
            .map(|n| SignalSpec::scalar(n))
            .collect()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let mut writes = vec![Slot::Effort(0)];
        let mut reads = vec![Slot::Flow(0), Slot::Input(0)];
        if self.spec.winch {
            writes.push(Slot::Effort(1));
            reads.push(Slot::Flow(1));
        }
        writes.extend((0..PAYLOAD_OUTPUTS.len()).map(Slot::Output));
        vec![Stage { writes, reads }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let a = self.read_at(io);
        {
            let mut ws = self.ws.borrow_mut();
            let (frames, q_force) = &mut *ws;
            // e = −Jᵀ F_tip
            q_force.fill(0.0);
            self.arm
                .pose_in(io.input(0), frames)
                .add_point_force(&self.tip, &a.on_tip, q_force);
            for (k, f) in q_force.iter().enumerate() {
                io.set_e(0, k, -f);
            }
        }
        if self.spec.winch {
            io.set_e(1, 0, a.tension);
        }
        let x = io.states();
        let m = self.spec.mass;
        let length = if self.spec.winch {
            x[4]
        } else {
            self.spec.length
        };
        let v = [
            x[0],
            x[1],
            x[2] / m,
            x[3] / m,
            a.tension,
            length,
            a.stretch,
            a.on_tip.x,
            a.on_tip.y,
            a.contact,
            a.friction,
            a.deck,
            a.tip[0],
            a.tip[1],
        ];
        debug_assert_eq!(OUT_FX, 7);
        for (k, y) in v.into_iter().enumerate() {
            io.set_y(k, 0, y);
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        let a = self.read_at(io);
        let x = io.states();
        let m = self.spec.mass;
        dx[0] = x[2] / m;
        dx[1] = x[3] / m;
        dx[2] = -a.tension * a.e.x + a.friction;
        dx[3] = -m * self.gravity - a.tension * a.e.y + a.contact;
        if self.spec.winch {
            dx[4] = -io.f_in(1, 0);
        }
    }
}
