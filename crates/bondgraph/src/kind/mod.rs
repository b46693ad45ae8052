//! Element kinds as data: what a model file may write for each kind, and how it is built.
//!
//! A kind declares its parameters once, beside its law ([`ParamDecl`]: name, unit, default,
//! allowed range, one line of description), and names a builder that reads them through
//! [`Params`]. Everything else comes from that one declaration: the loader's reading and its
//! errors (missing, misspelt with a suggestion, out of range naming the range, wrong unit),
//! `bg-sim kinds NAME`, and the parameter tables of the documentation (a test holds them to
//! the declarations).
//!
//! ```
//! use bondgraph::kind::{KindDecl, ParamDecl, Params, BuildError};
//! use bondgraph::{Element, Resistor};
//!
//! const PARAMS: &[ParamDecl] = &[
//!     ParamDecl::modulated("r", "Pa·s/m³", "resistance").positive(),
//! ];
//! fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
//!     Ok(Box::new(Resistor::new(p.modulated("r")?)?))
//! }
//! pub const DAMPER: KindDecl = KindDecl::element("example.damper", "linear damper", PARAMS, build)
//!     .example("r = 1e9");
//! assert_eq!(DAMPER.param("r").map(|d| d.unit), Some("Pa·s/m³"));
//! ```
//!
//! A kind may instead expand into a sub-graph ([`Composite`]): members named
//! `<instance>_<local>` ([`member_name`]), internal bonds, and exposed ports.

mod composite;
mod decl;
mod params;
mod suggest;
pub mod units;

pub use composite::{member_name, Composite, Expanded};
pub use decl::{
    number, Build, Change, CompositeBuilder, Default, ElementBuilder, KindDecl, ParamDecl,
    ParamType, Range, Simplification,
};
pub use params::{BuildError, BuildErrorKind, MatrixEntry, MatrixParam, Params};
pub use suggest::{similar, suggest};
