//! # bg-model: bond-graph models in TOML
//!
//! A model file reads like the diagram it describes:
//!
//! ```toml
//! title = "Mass–spring–damper"
//! [parameters]
//! m = 1.0
//! k = 100.0
//! [elements]
//! mass   = { kind = "I", m = "m" }
//! spring = { kind = "C", k = "k", q0 = 0.01 }
//! damper = { kind = "R", r = 0.4 }
//! v      = { kind = "1" }
//! [bonds]
//! b1 = "v -> mass"
//! b2 = "v -> spring"
//! b3 = "v -> damper"
//! [simulation]
//! t_end = 10.0
//! ```
//!
//! `docs/model-format.md` documents the format.
//!
//! ## Contents
//! Loading, a stage per module of [`load`]:
//! 1. parse: the file (after `--set`, [`overrides`]) as TOML with spans into typed sections;
//! 2. resolve: `[parameters]` and their expressions ([`expr`]);
//! 3. build: each entry through its kind's declaration ([`Registry`], [`reader`]'s
//!    [`ElementSpec`]) into elements, composites expanded;
//! 4. wire: bonds into the graph, signals, causality; then the equations;
//! 5. the model: initial values (a steady start, [`steady`]), settings ([`solver`]),
//!    outputs, checks, events ([`Model`]).
//!
//! [`Model::load`] reports the first problem, [`inspect`] every one (`bg-sim check`),
//! [`structure`] stops at the graph and its causality (`bg-sim graph`). Every problem is a
//! [`ModelError`] ([`error`]): file, line, column, element, message, hint, source.
//!
//! External inputs and data: `[inputs]` (signals set from outside, [`Model::inputs`],
//! [`Model::set_inputs_from_csv`]), [`data`] (CSV files with line/column errors), [`tables`]
//! (`[tables]`: 1-D and 2-D lookup tables called like functions, with exact derivatives).
//!
//! Around a model: [`scene`] (switches between richer and cheaper scenes), [`plots`]
//! (`[[plot]]` tables), [`describe`] (a kind's parameters, for `bg-sim kinds`).
//!
//! ## Element kinds
//! [`Registry::with_core`] knows the core kinds ([`bondgraph::kinds`]); domain crates hand
//! over theirs with [`Registry::add`]. Each kind is a [`bondgraph::KindDecl`]: parameters
//! declared as data, read for its builder by an [`ElementSpec`], which turns every problem
//! into a [`ModelError`] at the parameter's line.
//!
//! ## Expressions
//! Parameters and element values may be expressions: `"pi/4*d^2"`, `"1/k"`, or, where an
//! element allows modulation, functions of signals and time: `"1 + 0.1*spring.q"`.

pub mod data;
pub mod describe;
pub mod error;
pub mod expr;
pub mod load;
pub mod overrides;
pub mod plots;
pub mod reader;
pub mod registry;
pub mod scene;
pub mod sensitivity;
pub mod steady;
pub mod tables;

pub use data::DataFile;
pub use describe::{describe, parameter_table, KindReport};
pub use error::{ErrorKind, ModelError};
pub use load::{
    energy_audit, inspect, solver, structure, Check, CheckResult, EnergyRun, Entry, Extrapolate,
    Inspection, Model, Stepping, Structure, UnknownSolver,
};
pub use plots::{Panel, Plot, Series};
pub use reader::{ElementSpec, RawValue};
pub use registry::Registry;
pub use scene::{Choice, Scene, Switch};
pub use sensitivity::Sensitivities;
pub use steady::SteadyReport;
