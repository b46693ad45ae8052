//! # bondgraph: port-based bond graphs, causality, state equations and stiff simulation
//!
//! A mass–spring–damper pushed by a constant force, built, assigned causality, assembled and
//! run:
//!
//! ```
//! use bondgraph::*;
//! let mut g = BondGraph::new();
//! g.add("force", EffortSource::new(1.0))?;
//! g.add("v", OneJunction)?;
//! g.add("mass", Inertia::new(2.0, 0.0)?)?;
//! g.add("spring", Capacitor::new(1.0 / 50.0, 0.0)?)?;
//! g.add("damper", Resistor::new(3.0)?)?;
//! for (from, to) in [("force", "v"), ("v", "mass"), ("v", "spring"), ("v", "damper")] {
//!     g.connect_names(from, to)?;
//! }
//! let mut eqs = StateEquations::new(assign_causality(g)?)?;
//! let settings = Settings { t_end: 20.0, ..Settings::default() };
//! let outputs = [Output { name: "x".into(), probe: eqs.probe("spring.q").unwrap() }];
//! let x0 = eqs.initial_state();
//! let run = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
//! assert!(run.error.is_none());
//! let x_end = *run.trajectory.column("x").unwrap().last().unwrap();
//! assert!((x_end - 1.0 / 50.0).abs() < 1e-4); // static deflection F/k
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Building a graph
//! [`BondGraph`] holds named elements and bonds (half-arrow `from → to`, multibonds of any
//! dimension). Elements implement the small [`Element`] trait; the basic ones are in
//! [`elements`]: [`EffortSource`], [`FlowSource`], [`Resistor`], [`Capacitor`], [`Inertia`],
//! [`Transformer`] (TF/MTF), [`MatrixTransformer`], [`Gyrator`], [`ZeroJunction`],
//! [`OneJunction`], and the signal blocks [`Lag`], [`PController`], [`SignalFunction`].
//! Other crates add kinds by implementing [`Element`]; modulation goes through named signals
//! ([`Param`], [`Element::signal_inputs`]).
//!
//! ## External inputs
//! An [`Input`] element is a signal set from outside the model (a force, a valve command,
//! recorded data): its value is published under its bare name, held or following a
//! [`Series`] (linear or hold). [`StateEquations`] lists the inputs and sets them by index or
//! name (`inputs`, `set_input`, `set_input_by_name`, `set_input_series`,
//! `input_breakpoints`, `input_signal_offset` for derivatives with respect to an input);
//! [`simulate()`] stops and restarts at the series' breakpoints unless told not to.
//!
//! ## Element kinds
//! [`kind`] declares what a model file may write for each element kind: its parameters as data
//! ([`ParamDecl`]: name, unit, default, range, description), its builder reading them through
//! [`Params`], and [`Composite`]s — sub-graphs with exposed ports and the one naming rule of
//! their members.
//!
//! ## Causality
//! [`assign_causality`] runs SCAP and returns a [`CausalGraph`], or refuses derivative
//! causality and causal conflicts with a [`CausalityError`] naming the elements and bonds.
//!
//! ## Equations
//! [`StateEquations::new`] orders every element's stages into an evaluation plan computing
//! dx/dt = f(t, x) and every effort, flow and signal, and refuses algebraic loops.
//!
//! ## Energy
//! [`energy`] audits a run ([`simulate_audited`] with an [`EnergyAudit`]): per element the
//! energy supplied, stored, dissipated and its activity ∫|P| dt, by each element's
//! [`EnergyRole`], integrated on the dense output after every accepted step.
//!
//! ## Steady states and modes
//! [`solve_steady`] solves chosen unknown states for as many conditions (state derivatives or
//! states held at values) by Newton's method with the exact Jacobian ([`equilibrium`]).
//! [`modes`](fn@modes) linearises at a state and lists every eigenvalue as frequency, damping ratio and
//! time constant with the participation of each state ([`modes`](mod@modes) module).
//! [`linearize`](fn@linearize) gives the linear model (A, B, C, D) at an operating point, all
//! four exact, with poles, frequency response and Bode data ([`linearize`](mod@linearize)
//! module).
//!
//! ## Simulation
//! [`simulate()`] integrates with every [`Method`] behind one solver interface — our Radau IIA
//! (order 5, the default) and diffsol's BDF, ESDIRK34, TR-BDF2, Tsit45 — with the exact
//! Jacobian ([`StateEquations::jacobian`]), output times, scheduled [`Event`]s, limits and
//! [`Statistics`], and keeps the rows computed when it fails. [`radau`] is the standalone
//! Radau IIA integrator: [`Radau5`] over an [`OdeSystem`], stepped towards stop times, with
//! dense output and restarts. [`Simulation`] is a run advanced call by call (a controller
//! outside the model), keeping the solver's state between calls.

pub mod bond;
pub mod causality;
pub mod element;
pub mod elements;
pub mod energy;
pub mod equations;
pub mod equilibrium;
pub mod error;
pub mod graph;
pub mod io;
pub mod kind;
pub mod kinds;
pub mod linearize;
pub mod local_jacobian;
pub mod modes;
pub mod partials_check;
pub mod sensitivity;
/// The Radau IIA integrator, from the solver crate (`bg-solver`), re-exported.
pub use bg_solver::radau;
pub mod simulate;
#[cfg(test)]
mod test_models;

pub use bond::{Bond, BondId, ElementId, Endpoint, PortCausality};
pub use causality::{assign_causality, CausalGraph};
pub use element::{
    CausalRule, Element, Io, Limit, Param, PortSpec, Ports, SignalSpec, Slot, Stage, StateSpec,
    Watch,
};
pub use elements::*;
pub use energy::{ElementEnergy, EnergyAudit, EnergyReport, EnergyRole};
pub use equations::{LengthMismatch, Probe, StateEquations, StateInfo, Subset};
pub use equilibrium::{
    solve_steady, steady_size_error, Condition, Equilibrium, EquilibriumError, Settle,
    SteadyRequest, MAX_STEADY_STATES, MAX_STEADY_UNKNOWNS, OWN_SCALE_FRACTION,
};
pub use error::{CausalityError, Error, GraphError, ParamError, SimulationError};
pub use graph::{BondGraph, Node};
pub use kind::{BuildError, Composite, KindDecl, ParamDecl, Params};
pub use linearize::{linearize, BodePoint, Linearization, MAX_BODE_STATES, MAX_LINEARIZE_STATES};
pub use local_jacobian::{LocalJacobian, LocalShape};
pub use modes::{modes, modes_of, stiffness_ratio, Mode, ModesError, MAX_MODES_STATES};
/// The dense matrix type of [`StateEquations::jacobian`].
pub use nalgebra::DMatrix;
pub use partials_check::check_partials;
pub use radau::{OdeSystem, Radau5, RadauError, RadauOptions, RadauStats, StepReport};
pub use simulate::{
    check_in_memory, simulate, simulate_audited, simulate_into, Event, Method, Outcome, Output,
    RowSink, Settings, Simulation, Statistics, Trajectory, WatchReport, MAX_OUTPUT_ROWS,
    MAX_VALUES_IN_MEMORY, MIN_RTOL,
};
