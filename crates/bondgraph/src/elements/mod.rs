//! The basic bond-graph elements. One file per element: its law, its causality, its tests.
//!
//! | symbol | type | law (power into the element positive) |
//! |---|---|---|
//! | `Se` | [`EffortSource`] | e = e_s(t, signals) |
//! | `Sf` | [`FlowSource`] | f_in = f_s(t, signals) |
//! | `R` | [`Resistor`] | e = r·f_in |
//! | `C` | [`Capacitor`] | dq/dt = f_in, e = q/c |
//! | `I` | [`Inertia`] | dp/dt = e, f_in = p/m |
//! | `TF`, `MTF` | [`Transformer`] | e₁ = m·e₂, f_in₂ = −m·f_in₁ |
//! | `MTF` (matrix) | [`MatrixTransformer`] | e₁ = T·e₂, f_in₂ = −Tᵀ·f_in₁ |
//! | `GY`, `MGY` | [`Gyrator`] | e₁ = −r·f_in₂, e₂ = r·f_in₁ |
//! | `0` | [`ZeroJunction`] | common effort, Σ f_in = 0 |
//! | `1` | [`OneJunction`] | common flow, Σ s·e = 0 |
//! | `lag` | [`Lag`] | τ·dy/dt = u − y |
//! | `p_control` | [`PController`] | y = clamp(K·(r − u), lo, hi) |
//! | `signal` | [`SignalFunction`] | y = g(t, signals) |
//! | `Sf_position` | [`PositionSource`] | f_in = −ẋ(t) of a prescribed position x(t) |
//! | `integrator` | [`Integrator`] | dy/dt = u, limits without windup, reset |
//! | (`[inputs]`) | [`Input`] | y = u(t), set from outside |

pub(crate) mod capacitor;
pub(crate) mod gyrator;
pub(crate) mod inertia;
pub(crate) mod input;
pub(crate) mod integrator;
pub(crate) mod junction;
pub(crate) mod lag;
pub(crate) mod matrix_transformer;
pub(crate) mod p_controller;
pub(crate) mod position_source;
pub(crate) mod resistor;
pub(crate) mod signal_function;
pub(crate) mod sources;
pub(crate) mod transformer;

pub use capacitor::Capacitor;
pub use gyrator::Gyrator;
pub use inertia::Inertia;
pub use input::{Input, InputSpec, Interp, Series};
pub use integrator::Integrator;
pub use junction::{OneJunction, ZeroJunction};
pub use lag::Lag;
pub use matrix_transformer::{
    apply_effort, apply_flow, effort_partials, flow_partials, MatrixTransformer, ModulusLaw,
};
pub use p_controller::PController;
pub use position_source::PositionSource;
pub use resistor::Resistor;
pub use signal_function::SignalFunction;
pub use sources::{EffortSource, FlowSource};
pub use transformer::Transformer;

/// Names for the `n` components of a vector state: `p` for n = 1, else `p[0]`, `p[1]`, …
pub fn component_names(base: &str, n: usize) -> Vec<String> {
    if n == 1 {
        vec![base.to_owned()]
    } else {
        (0..n).map(|k| format!("{base}[{k}]")).collect()
    }
}
