//! Loading a model file, a stage per module: [`parse`](self) (TOML with spans → typed
//! sections), resolve (parameters and expressions, with `--set` applied to the text by
//! [`crate::overrides`]), build (kinds → elements, composites expanded), wire (bonds →
//! graph, signals, causality), then the equations and what the model keeps: initial
//! values, settings, outputs, checks and events ([`Model`]). Every error names the file,
//! the line and column, the element and a hint; [`inspect`] collects every problem,
//! [`Model::load`] reports the first.

mod build;
mod checks;
mod energy;
mod events;
mod initial;
mod inputs;
mod inspect;
mod linear;
mod model;
mod outputs;
mod parse;
mod resolve;
mod sea;
mod settings;
mod source;
mod stepping;
mod structure;
mod tables;
mod wire;

pub use checks::{Check, CheckResult};
pub use energy::{energy_audit, EnergyRun};
pub use inputs::Extrapolate;
pub use inspect::{inspect, Inspection};
pub use model::Model;
pub use outputs::{valid_column_name, MAX_COLUMN_NAME};
pub use parse::MAX_FILE_BYTES;
pub use settings::{solver, UnknownSolver};
pub use stepping::Stepping;
pub use structure::{structure, Entry, Structure};
