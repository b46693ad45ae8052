//! # bg-fmu: a bg-sim model as an FMI co-simulation FMU
//!
//! One shared library (`cargo build -p bg-fmu` → `libbg_fmu.so`) exports the FMI 2.0
//! (`fmi2*`) and FMI 3.0 (`fmi3*`) co-simulation functions and runs whatever model file the
//! FMU carries in `resources/`: the model is loaded at instantiation, so the same library
//! serves every model. `bg-sim fmu` writes the archive ([`package`]); `docs/fmu.md` tells
//! how to use it.
//!
//! ## Contents
//! - [`description`]: the FMU's variables (value references) and `modelDescription.xml`;
//! - [`instance`]: one instance in safe Rust — loading, inputs, parameters, the
//!   co-simulation step on [`bg_model::Stepping`], saved states;
//! - [`fmi2`], [`fmi3`]: the C entry points, thin: pointers in, [`instance::Instance`]
//!   calls, statuses out;
//! - [`ffi`]: what they share — the guard that turns a panic into a logged `Fatal`, slices
//!   and strings from the importer's pointers, resource locations;
//! - [`package`]: the `.fmu` archive.
//!
//! The C boundary needs `unsafe`; this crate alone allows it (its `[lints]`), and every
//! `unsafe` block says why it is sound.
#![deny(unsafe_op_in_unsafe_fn)]

pub mod description;
pub mod ffi;
pub mod fmi2;
pub mod fmi3;
pub mod instance;
pub mod package;

pub use description::{Description, FmiVersion};
pub use instance::{Instance, Phase, Status};
pub use package::{export, ExportError, Exported};
