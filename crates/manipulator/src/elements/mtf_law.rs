//! The matrix-MTF law shared by the actuator and lumped-mass transformers, in the core's
//! convention (`bondgraph::MatrixTransformer`): `e₁ = T e₂`, `f_in₂ = −Tᵀ f_in₁`. Power is
//! conserved for every T: `e₁ᵀf_in₁ + e₂ᵀf_in₂ = e₂ᵀTᵀf_in₁ − e₂ᵀTᵀf_in₁ = 0`.

use bondgraph::{Io, LocalJacobian, Slot, Stage};
use nalgebra::DMatrix;

/// Stage 0 writes e₁ from e₂, stage 1 writes f₂ from f₁; both read the modulating signal
/// input 0.
pub(crate) fn stages() -> Vec<Stage> {
    vec![
        Stage {
            writes: vec![Slot::Effort(0)],
            reads: vec![Slot::Effort(1), Slot::Input(0)],
        },
        Stage {
            writes: vec![Slot::Flow(1)],
            reads: vec![Slot::Flow(0), Slot::Input(0)],
        },
    ]
}

/// `e₁ = T e₂`.
pub(crate) fn set_effort(io: &mut Io<'_>, t: &DMatrix<f64>) {
    bondgraph::apply_effort(io, t);
}

/// `f_in₂ = −Tᵀ f_in₁`.
pub(crate) fn set_flow(io: &mut Io<'_>, t: &DMatrix<f64>) {
    bondgraph::apply_flow(io, t);
}

/// `∂e₁/∂e₂ = T` (the modulation's partials are the caller's).
pub(crate) fn effort_partials(jac: &mut LocalJacobian<'_>, t: &DMatrix<f64>) {
    bondgraph::effort_partials(jac, t);
}

/// `∂f_in₂/∂f_in₁ = −Tᵀ` (the modulation's partials are the caller's).
pub(crate) fn flow_partials(jac: &mut LocalJacobian<'_>, t: &DMatrix<f64>) {
    bondgraph::flow_partials(jac, t);
}
