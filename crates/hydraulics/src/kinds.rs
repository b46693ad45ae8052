//! Every `hydraulics.*` kind, each declared beside its law (`docs/hydraulics.md` has their
//! tables): the list a model loader registers.

use bondgraph::KindDecl;

use crate::{
    accumulator, chamber, cylinder, end_stop, friction, laminar, leakage, line, machine, orifice,
    piston, tank, valve,
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
    accumulator::KIND,
    line::KIND,
    tank::KIND,
    machine::PUMP,
    machine::MOTOR,
    friction::KIND,
];
