//! The bond-graph elements of the manipulator (section 4, Fig. 5).
//!
//! | kind | type | ports | law (power into the element positive) |
//! |---|---|---|---|
//! | `manipulator.i_field` | [`ArmInertia`] | `1`: n | states p, q; f_in = u = M(q)⁻¹p; ṗ = e + E(q, u); q̇ = u (eqs. 43, 64) |
//! | `manipulator.c_field` | [`ArmCompliance`] | `1`: n | e = −G(q) + K q (eq. 65), q read from the I-field |
//! | `manipulator.r_field` | [`ArmDamping`] | `1`: n | e = D f_in, D diagonal |
//! | `manipulator.actuator_mtf` | [`ActuatorTransformer`] | `1`: n, `2`: n_act | e₁ = τ_b e₂, f_in₂ = −τ_bᵀ f_in₁ (eq. 66) |
//! | `manipulator.lumped_mass_mtf` | [`LumpedMassTransformer`] | `1`: n, `2`: 2m | e₁ = J_cᵀ e₂, f_in₂ = −J_c f_in₁ (eq. 70) |
//! | `I` (diagonal) | [`lumped_masses`] | `1`: 2m | ṗ = e, f_in = M_c⁻¹ p (eq. 75) |
//! | `manipulator.lumped_gravity` | [`LumpedGravity`] | `1`: 2m | e = −g [0 m₁ 0 m₂ …] (eq. 76) |
//! | `manipulator.reactions` | [`ArmReactions`] | — | publishes ρ (eqs. 84–98); on a moving base also the pedestal's reaction |
//! | `manipulator.base` | [`BaseMotion`] | — | publishes the base's motion and apparent gravity ([`base`](crate::base)) |
//! | `manipulator.wire_payload` | [`WirePayload`] | `1`: n, `wire`: 1 | a point mass on an elastic wire from the tip, slack-able, optional landing |
//! | `manipulator.base_loads` | [`BaseLoads`] | `1`: n | e = −G(q; f − f₀), the loads of the base's acceleration |
//!
//! The MTFs follow the core's matrix-MTF convention: draw port 1 *from the MTF into* the
//! arm's 1-junction; then e₂ is the force on the mechanism (the cylinder force F_c, positive
//! pushing the pins apart; the spring–damper forces on the pins, frame 0) and f_in₂ the
//! corresponding rate (l̇, pin velocities).

mod actuator_mtf;
mod at_last_q;
mod base_loads;
mod base_motion;
mod c_field;
mod i_field;
mod lumped_gravity;
mod lumped_mass_mtf;
mod lumped_masses;
mod mtf_law;
mod r_field;
mod reaction_block;
mod wire_payload;

pub use actuator_mtf::ActuatorTransformer;
pub(crate) use at_last_q::same_bits;
pub use base_loads::BaseLoads;
pub use base_motion::{BaseMotion, BASE_OUTPUTS, OUT_ALPHA, OUT_FIELD, OUT_OMEGA};
pub use c_field::ArmCompliance;
pub use i_field::ArmInertia;
pub use lumped_gravity::LumpedGravity;
pub use lumped_mass_mtf::LumpedMassTransformer;
pub use lumped_masses::lumped_masses;
pub use r_field::ArmDamping;
pub use reaction_block::{ArmReactions, ReactionInputs};
pub use wire_payload::{Landing, WirePayload, WireSpec, PAYLOAD_OUTPUTS};
