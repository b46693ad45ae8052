//! Every `hydraulics.*` kind, each declared beside its law (`docs/hydraulics.md` has their
//! tables): the list a model loader registers.

use bondgraph::KindDecl;

use crate::{
    accumulator, chamber, check_valve, counterbalance_valve, cylinder, directional_valve, end_stop,
    flow_control_valve, friction, laminar, leakage, line, ls_line, ls_pump, ls_section, machine,
    orifice, pilot_check_valve, piston, pressure_reducing_valve, relief_valve, sequence_valve,
    shuttle_valve, tank, valve, valve_2_2, valve_3_2,
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
    relief_valve::KIND,
    check_valve::KIND,
    pilot_check_valve::KIND,
    counterbalance_valve::KIND,
    sequence_valve::KIND,
    pressure_reducing_valve::KIND,
    directional_valve::KIND,
    valve_2_2::KIND,
    valve_3_2::KIND,
    flow_control_valve::KIND,
    machine::PUMP,
    machine::MOTOR,
    friction::KIND,
    ls_pump::KIND,
    shuttle_valve::KIND,
    ls_line::KIND,
    ls_section::KIND,
];
