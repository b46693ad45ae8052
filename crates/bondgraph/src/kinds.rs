//! The core's element kinds, each declared beside its law in `elements/`: the list a model
//! loader registers (`Se Sf R C I TF MTF GY MGY 0 1 lag p_control signal Sf_position
//! integrator`).

use crate::elements::{
    capacitor, gyrator, inertia, integrator, junction, lag, matrix_transformer, p_controller,
    position_source, resistor, signal_function, sources, transformer,
};
use crate::KindDecl;

/// Every core kind.
pub const KINDS: &[KindDecl] = &[
    sources::SE,
    sources::SF,
    resistor::KIND,
    capacitor::KIND,
    inertia::KIND,
    transformer::KIND,
    matrix_transformer::KIND,
    gyrator::GY,
    gyrator::MGY,
    junction::ZERO,
    junction::ONE,
    lag::KIND,
    p_controller::KIND,
    signal_function::KIND,
    position_source::KIND,
    integrator::KIND,
];
