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
//! ## Loading
//! [`Model::load`] parses, applies `--set` overrides ([`overrides::apply`]), builds every
//! element through the [`Registry`], assigns causality and assembles the equations. Every
//! failure is a [`ModelError`] with file, line, column, element and hint.
//! [`inspect`] goes as far as it can and reports what it found (`bg-sim check`);
//! [`structure`] stops at the bond graph and its causality, for drawing (`bg-sim graph`).
//!
//! ## Scene switches
//! `[scene]` declares the switches between richer and cheaper scenes (modes, lumped masses,
//! …), each a `--set` key with its choices; [`Model::scene`] exposes them ([`scene`]).
//!
//! ## Element kinds
//! [`Registry::with_core`] knows the core kinds ([`bondgraph::kinds`]); domain crates hand
//! over theirs with [`Registry::add`]. Each kind is a [`bondgraph::KindDecl`]: parameters
//! declared as data, read for its builder by an [`ElementSpec`] ([`reader`]), which turns
//! every problem into a [`ModelError`] at the parameter's line.
//!
//! ## Expressions
//! Parameters and element values may be expressions ([`expr`]): `"pi/4*d^2"`, `"1/k"`, or,
//! where an element allows modulation, functions of signals and time: `"1 + 0.1*spring.q"`.

pub mod describe;
pub mod error;
pub mod expr;
pub mod load;
pub mod overrides;
pub mod plots;
pub mod reader;
pub mod registry;
pub mod scene;
pub mod steady;

pub use describe::{describe, parameter_table, KindReport};
pub use error::{ErrorKind, ModelError};
pub use load::{inspect, structure, Check, CheckResult, Entry, Inspection, Model, Structure};
pub use plots::{Panel, Plot, Series};
pub use reader::{ElementSpec, RawValue};
pub use registry::Registry;
pub use scene::{Choice, Scene, Switch};
pub use steady::SteadyReport;
