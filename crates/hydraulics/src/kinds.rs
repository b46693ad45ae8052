//! Every `hydraulics.*` kind, each declared beside its law (`docs/hydraulics.md` has their
//! tables): the list a model loader registers.

use bondgraph::KindDecl;

use crate::{
    chamber, cylinder, end_stop, friction, laminar, leakage, machine, orifice, piston, valve,
};

/// Every kind of this crate.
pub const KINDS: &[KindDecl] = &[
    chamber::KIND,
    piston::KIND,
    end_stop::KIND,
    leakage::INTERNAL,
    leakage::TO_TANK,
    orifice::KIND,
    valve::KIND,
    cylinder::KIND,
    laminar::KIND,
    machine::PUMP,
    machine::MOTOR,
    friction::KIND,
];
