//! The [`Element`] trait: what every bond-graph element, field, junction and signal block
//! implements, and the [`Io`] view through which it reads and writes its variables.
//!
//! Sign convention (see `docs/conventions.md`): an element sees its ports with *power in*
//! positive. [`Io::f_in`] is the flow into the element (the bond's flow if the half-arrow points
//! at the element, its negative otherwise); efforts are never sign-flipped.

use std::fmt::Debug;

use crate::bond::PortCausality;
pub use crate::io::{Io, Layout, PortLayout, Slot, Source};
use crate::local_jacobian::LocalJacobian;

/// Port signature of an element.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Ports {
    /// Fixed ports, in order, each with its dimension (`None`: takes the bond's dimension).
    Fixed(Vec<PortSpec>),
    /// Any number of ports of one common dimension (junctions).
    Any,
}

/// One port of an element.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PortSpec {
    /// Port name used in model files (`"1"`, `"2"`, `"mech"`, …).
    pub name: String,
    /// Dimension of the port, or `None` if it adapts to the bond.
    pub dim: Option<usize>,
}

impl PortSpec {
    /// A port of fixed dimension.
    #[must_use]
    pub fn new(name: &str, dim: usize) -> Self {
        Self {
            name: name.to_owned(),
            dim: Some(dim),
        }
    }
    /// A port that takes the dimension of its bond.
    #[must_use]
    pub fn any_dim(name: &str) -> Self {
        Self {
            name: name.to_owned(),
            dim: None,
        }
    }
}

/// A state of an element (a momentum, a displacement, a block state).
#[derive(Clone, Debug, PartialEq)]
pub struct StateSpec {
    /// Name, unique within the element (`p`, `q`, `x_v`, `q[2]`).
    pub name: String,
    /// Initial value.
    pub initial: f64,
    /// Typical magnitude: the absolute tolerance of this state is `atol · nominal`.
    pub nominal: f64,
}

impl StateSpec {
    /// A state with nominal magnitude 1.
    #[must_use]
    pub fn new(name: &str, initial: f64) -> Self {
        Self {
            name: name.to_owned(),
            initial,
            nominal: 1.0,
        }
    }
    /// Set the nominal magnitude used to scale the absolute tolerance.
    #[must_use]
    pub fn nominal(mut self, nominal: f64) -> Self {
        self.nominal = nominal;
        self
    }
}

/// A named signal an element reads or publishes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SignalSpec {
    /// Local name (`x_v`, `y`).
    pub name: String,
    /// Number of scalars (1 for a scalar signal).
    pub dim: usize,
}

impl SignalSpec {
    /// A scalar signal.
    #[must_use]
    pub fn scalar(name: &str) -> Self {
        Self {
            name: name.to_owned(),
            dim: 1,
        }
    }
}

/// The causal constraints of an element, used by [`assign_causality`](crate::assign_causality).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CausalRule {
    /// One admissible pattern, not a storage (Se, Sf, a one-way MTF): applied first.
    Fixed(Vec<PortCausality>),
    /// A storage element in integral causality; any other pattern is derivative causality, refused.
    Integral(Vec<PortCausality>),
    /// Any one of these patterns, in order of preference (R).
    Resistive(Vec<Vec<PortCausality>>),
    /// Exactly one port has this causality, all others the opposite
    /// (0-junction: `FlowOut`; 1-junction: `EffortOut`; TF: either).
    ExactlyOne(PortCausality),
    /// All ports have the same causality (GY).
    AllEqual,
    /// No ports (signal blocks).
    None,
}

impl CausalRule {
    /// Whether `causality` (one entry per port) satisfies this rule.
    #[must_use]
    pub fn admits(&self, causality: &[PortCausality]) -> bool {
        match self {
            Self::Fixed(p) | Self::Integral(p) => p.as_slice() == causality,
            Self::Resistive(ps) => ps.iter().any(|p| p.as_slice() == causality),
            Self::ExactlyOne(c) => causality.iter().filter(|x| *x == c).count() == 1,
            Self::AllEqual => causality.windows(2).all(|w| w[0] == w[1]),
            Self::None => causality.is_empty(),
        }
    }
}

/// One step of an element's computation: it writes `writes` from `reads` (and states and time).
///
/// Elements split their work into stages so that the evaluation plan has no false algebraic
/// loops: a 0-junction distributes its effort and sums its flows in two independent stages.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Stage {
    /// Variables computed by this stage.
    pub writes: Vec<Slot>,
    /// Variables this stage needs.
    pub reads: Vec<Slot>,
}

impl Stage {
    /// The default: one stage writing every output from every input.
    #[must_use]
    pub fn single(causality: &[PortCausality], n_inputs: usize, n_outputs: usize) -> Vec<Stage> {
        let mut stage = Stage::default();
        for (i, c) in causality.iter().enumerate() {
            match c {
                PortCausality::EffortOut => {
                    stage.writes.push(Slot::Effort(i));
                    stage.reads.push(Slot::Flow(i));
                }
                PortCausality::FlowOut => {
                    stage.writes.push(Slot::Flow(i));
                    stage.reads.push(Slot::Effort(i));
                }
            }
        }
        stage.reads.extend((0..n_inputs).map(Slot::Input));
        stage.writes.extend((0..n_outputs).map(Slot::Output));
        vec![stage]
    }

    /// A stage computing outputs from states only (storage elements): writes every
    /// `EffortOut` effort / `FlowOut` flow and all signal outputs, reading only signal inputs.
    #[must_use]
    pub fn from_states(
        causality: &[PortCausality],
        n_inputs: usize,
        n_outputs: usize,
    ) -> Vec<Stage> {
        let mut stage = Stage::default();
        for (i, c) in causality.iter().enumerate() {
            stage.writes.push(match c {
                PortCausality::EffortOut => Slot::Effort(i),
                PortCausality::FlowOut => Slot::Flow(i),
            });
        }
        stage.reads.extend((0..n_inputs).map(Slot::Input));
        stage.writes.extend((0..n_outputs).map(Slot::Output));
        vec![stage]
    }
}

/// A bond-graph element: its ports, causal constraints, states and constitutive law.
///
/// Only [`kind`](Element::kind), [`ports`](Element::ports), [`causal_rule`](Element::causal_rule)
/// and [`eval`](Element::eval) are required. Storage elements add [`states`](Element::states),
/// [`derivatives`](Element::derivatives) and usually [`stages`](Element::stages). Elements that
/// know their partial derivatives say them in [`stage_partials`](Element::stage_partials) and
/// [`derivative_partials`](Element::derivative_partials) (else the Jacobian differences them).
pub trait Element: Debug {
    /// Kind as written in model files: `"R"`, `"0"`, `"hydraulics.orifice"`.
    fn kind(&self) -> &str;

    /// Port signature.
    fn ports(&self) -> Ports;

    /// Causal constraints, given the number of attached ports.
    fn causal_rule(&self, n_ports: usize) -> CausalRule;

    /// States with their initial values.
    fn states(&self) -> Vec<StateSpec> {
        Vec::new()
    }

    /// Signals this element reads (resolved by name when the graph is built).
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        Vec::new()
    }

    /// Signals this element publishes as `<element>.<name>`.
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        Vec::new()
    }

    /// How the computation splits into stages for the assigned causality
    /// (default: one stage, every output from every input).
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        Stage::single(
            causality,
            self.signal_inputs().len(),
            self.signal_outputs().len(),
        )
    }

    /// Compute the variables written by `stage`.
    fn eval(&self, stage: usize, io: &mut Io<'_>);

    /// State derivatives `dx` (this element's slice), once every variable is known.
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        let _ = (io, dx);
    }

    /// Partial derivatives of the scalars `stage` writes with respect to the element's local
    /// variables (see [`LocalJacobian`] for the rows, columns and sign conventions).
    ///
    /// `io` holds the values at the evaluation point, including the stage's own writes; `jac`
    /// arrives zeroed. Return `true` if the entries are filled, `false` (the default) to let
    /// the core difference `eval` locally instead. Entries are exact derivatives where
    /// the law is smooth; at a kink (a clamp, an absolute value) either one-sided value.
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let _ = (stage, io, jac);
        false
    }

    /// Partial derivatives of the element's state derivatives (rows: its states, in order)
    /// with respect to its local variables (see [`LocalJacobian`]), after every variable is
    /// known. `jac` arrives zeroed. Return `true` if the entries are filled, `false` (the
    /// default) to let the core difference [`derivatives`](Element::derivatives) locally.
    fn derivative_partials(&self, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let _ = (io, jac);
        false
    }

    /// Whether the core's local differences of this element (where it gives no partials)
    /// are central whatever the number of perturbed scalars: for a law that loses digits to
    /// cancellation (a stiff wire's stretch, the small difference of two long distances),
    /// where forward differences at √ε would keep too few. `false` (the default): central up
    /// to a few scalars, forward above.
    fn central_differences(&self) -> bool {
        false
    }

    /// Whether every partial this element gives ([`stage_partials`](Element::stage_partials),
    /// [`derivative_partials`](Element::derivative_partials)) is the same at every (t, x): a
    /// junction's ±1, a constant ratio or resistance. The Jacobian then asks for them once,
    /// when its plan is compiled, and never again. `false` (the default) asks every time.
    fn partials_are_constant(&self) -> bool {
        false
    }

    /// States the simulator should watch over a run, every accepted step (a chamber's
    /// minimum pressure, with a warning below the tank pressure).
    fn watches(&self) -> Vec<Watch> {
        Vec::new()
    }

    /// Bounds on states: a run that reaches one stops there, exactly (by root finding), with
    /// [`SimulationError::LimitReached`](crate::SimulationError::LimitReached) and the
    /// element's message (a piston leaving its stroke with no end stop).
    fn limits(&self) -> Vec<Limit> {
        Vec::new()
    }

    /// Lengths the element has along its scalar mechanical ports, as (port, index into
    /// [`signal_outputs`](Self::signal_outputs) of the scalar signal holding the length):
    /// the distance whose rate of change is the port's flow (a cylinder's l = l0 + s, an
    /// arm's pin distance). Two such ports joined by bonds, directly or through 1-junctions
    /// (one velocity), describe one distance and must agree at the initial state
    /// ([`StateEquations::length_mismatches`](crate::StateEquations::length_mismatches)):
    /// geometry that cannot be assembled is refused before a run.
    fn port_lengths(&self) -> Vec<(usize, usize)> {
        Vec::new()
    }

    /// Energy stored at states `x` (this element's states), if the element stores any and
    /// it is a function of its own states: the energy audit's `stored` is then
    /// E(end) − E(start) ([`crate::energy`]), else the integral of its port power.
    fn stored_energy(&self, x: &[f64]) -> Option<f64> {
        let _ = x;
        None
    }

    /// What the element does with the power that enters it, for the energy audit
    /// ([`crate::energy`]): by default what its causal rule says
    /// ([`EnergyRole::from_rule`](crate::energy::EnergyRole::from_rule)); elements whose rule
    /// does not tell (a modulated flow source with two ports, a lossy machine, a field whose
    /// effort comes from another element's states) say it here.
    fn energy_role(&self, n_ports: usize) -> crate::energy::EnergyRole {
        crate::energy::EnergyRole::from_rule(&self.causal_rule(n_ports))
    }

    /// Power the element takes from outside the graph, not through a port (a pump driven at
    /// a set speed: its drive's T·ω), once every variable is known; `None` (the default):
    /// everything it exchanges passes its ports. The energy audit counts it as supplied and
    /// the difference from the power leaving its ports as the element's own losses.
    fn external_power(&self, io: &Io<'_>) -> Option<f64> {
        let _ = io;
        None
    }

    /// The external input this element is, if it is one ([`Input`](crate::Input): its signal
    /// is published under the element's bare name and set from outside the model).
    fn as_input(&self) -> Option<&crate::elements::Input> {
        None
    }
}

/// Bounds on one of an element's states (`f64::NEG_INFINITY` / `f64::INFINITY` for none).
#[derive(Clone, Debug, PartialEq)]
pub struct Limit {
    /// Index of the state within the element's states.
    pub state: usize,
    /// Lower bound.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
    /// What reaching it means, e.g. "the piston left its stroke".
    pub message: String,
    /// What to do about it, e.g. "add an end stop".
    pub hint: Option<String>,
}

/// A state whose minimum the simulator records over a run, at every accepted step.
#[derive(Clone, Debug, PartialEq)]
pub struct Watch {
    /// What it is, for the report (`pressure`).
    pub name: String,
    /// Index of the state within the element's states.
    pub state: usize,
    /// Warn when the minimum falls below this value.
    pub warn_below: Option<f64>,
    /// The warning's text (why it matters), e.g. "cavitation, which the model does not represent".
    pub warning: String,
}

/// The law of a modulated [`Param`]: `value = law(t, inputs)`.
pub type ParamLaw = Box<dyn Fn(f64, &[f64]) -> f64>;

/// The exact gradient law of a modulated [`Param`]: returns the value at `(t, inputs)` and
/// writes ∂value/∂inputₖ into `grad[k]` (one entry per input).
pub type ParamGradient = Box<dyn Fn(f64, &[f64], &mut [f64]) -> f64>;

/// A coefficient that is either constant or a function of time and scalar signal inputs
/// (a *modulated* parameter: the ratio of an MTF, the resistance of a valve, a source value).
pub enum Param {
    /// A constant.
    Const(f64),
    /// `value = law(t, inputs)`, reading the named scalar signals.
    Modulated {
        /// Names of the signals read, in the order `law` receives them.
        inputs: Vec<String>,
        /// The law.
        law: ParamLaw,
        /// Its exact gradient, if known (else [`Param::partials`] differences `law`).
        gradient: Option<ParamGradient>,
    },
}

/// Signal inputs a modulated parameter reads without allocating (more are allowed, slower).
pub const MAX_PARAM_INPUTS: usize = 16;

impl Param {
    /// A modulated parameter.
    pub fn modulated(inputs: Vec<String>, law: impl Fn(f64, &[f64]) -> f64 + 'static) -> Self {
        Self::Modulated {
            inputs,
            law: Box::new(law),
            gradient: None,
        }
    }
    /// A modulated parameter whose exact gradient is known: `gradient(t, u, grad)` returns
    /// the value and writes ∂value/∂uₖ into `grad[k]` (a compiled expression's forward mode,
    /// a lookup table's slope). [`Param::partials`] then uses it instead of differences.
    pub fn modulated_exact(
        inputs: Vec<String>,
        law: impl Fn(f64, &[f64]) -> f64 + 'static,
        gradient: impl Fn(f64, &[f64], &mut [f64]) -> f64 + 'static,
    ) -> Self {
        Self::Modulated {
            inputs,
            law: Box::new(law),
            gradient: Some(Box::new(gradient)),
        }
    }
    /// Signals read, as specs (scalar).
    #[must_use]
    pub fn signal_inputs(&self) -> Vec<SignalSpec> {
        match self {
            Self::Const(_) => Vec::new(),
            Self::Modulated { inputs, .. } => {
                inputs.iter().map(|n| SignalSpec::scalar(n)).collect()
            }
        }
    }
    /// Number of signal inputs.
    #[must_use]
    pub fn n_inputs(&self) -> usize {
        match self {
            Self::Const(_) => 0,
            Self::Modulated { inputs, .. } => inputs.len(),
        }
    }
    /// The constant value, if constant.
    #[must_use]
    pub fn constant(&self) -> Option<f64> {
        match self {
            Self::Const(v) => Some(*v),
            Self::Modulated { .. } => None,
        }
    }
    /// Value now; the parameter's inputs are the element's inputs `first..first + n_inputs`.
    #[inline]
    #[must_use]
    pub fn value(&self, io: &Io<'_>, first: usize) -> f64 {
        match self {
            Self::Const(v) => *v,
            Self::Modulated { inputs, law, .. } => modulated_value(inputs.len(), law, io, first),
        }
    }

    /// Partial derivatives of the value with respect to its inputs (the element's inputs
    /// `first..first + n_inputs`): calls `f(k, ∂value/∂u_k)` for each input k; nothing for
    /// a constant.
    ///
    /// With an exact gradient ([`Param::modulated_exact`]) the derivatives are exact;
    /// otherwise a law is a closure, so they are central differences of the law alone
    /// (step ∛ε·max(|u|, 1e-3); error about 1e-10 relative for smooth laws): cheap, and
    /// free of allocation for up to [`MAX_PARAM_INPUTS`] inputs.
    pub fn partials(&self, io: &Io<'_>, first: usize, mut f: impl FnMut(usize, f64)) {
        let Self::Modulated {
            inputs,
            law,
            gradient,
        } = self
        else {
            return;
        };
        let n = inputs.len();
        if let (Some(grad), true) = (gradient, n <= MAX_PARAM_INPUTS) {
            let mut u = [0.0; MAX_PARAM_INPUTS];
            let mut g = [0.0; MAX_PARAM_INPUTS];
            for (k, b) in u.iter_mut().take(n).enumerate() {
                *b = io.u(first + k);
            }
            let _ = grad(io.time(), &u[..n], &mut g[..n]);
            for (k, d) in g.iter().take(n).enumerate() {
                f(k, *d);
            }
            return;
        }
        let mut small = [0.0; MAX_PARAM_INPUTS];
        let mut large = Vec::new();
        let u: &mut [f64] = if n > MAX_PARAM_INPUTS {
            large.resize(n, 0.0);
            &mut large
        } else {
            &mut small[..n]
        };
        for (k, b) in u.iter_mut().enumerate() {
            *b = io.u(first + k);
        }
        let t = io.time();
        for k in 0..n {
            let v = u[k];
            let h = central_step(v, 1e-3);
            u[k] = v + h;
            let plus = law(t, u);
            u[k] = v - h;
            let minus = law(t, u);
            u[k] = v;
            f(k, (plus - minus) / (2.0 * h));
        }
    }
}

/// `law(t, u)` with u = the element's inputs `first..first + n` (no allocation for up to
/// [`MAX_PARAM_INPUTS`] inputs; one input, the common case, read into a register).
fn modulated_value(n: usize, law: &ParamLaw, io: &Io<'_>, first: usize) -> f64 {
    if n == 1 {
        return law(io.time(), &[io.u(first)]);
    }
    if n > MAX_PARAM_INPUTS {
        let v: Vec<f64> = (0..n).map(|k| io.u(first + k)).collect();
        return law(io.time(), &v);
    }
    let mut buf = [0.0; MAX_PARAM_INPUTS];
    for (k, b) in buf.iter_mut().take(n).enumerate() {
        *b = io.u(first + k);
    }
    law(io.time(), &buf[..n])
}

/// The step of a central difference at `v`: ∛ε·max(|v|, `floor`), rounded so that v ± h are
/// exact.
pub(crate) fn central_step(v: f64, floor: f64) -> f64 {
    let h = 6.055_454_452_393_343e-6 * v.abs().max(floor);
    (v + h) - v
}

impl Debug for Param {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Const(v) => write!(f, "{v}"),
            Self::Modulated { inputs, .. } => write!(f, "law({})", inputs.join(", ")),
        }
    }
}

impl From<f64> for Param {
    fn from(v: f64) -> Self {
        Self::Const(v)
    }
}
