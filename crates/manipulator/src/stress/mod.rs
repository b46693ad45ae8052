//! Stress recovery along the links: section forces N(x), V(x), M(x) by force summation
//! ([`summation`]), the modal bending moment EI·w''(x) beside it ([`modal`]), the outer-fibre
//! normal stresses of a declared cross-section ([`section`]), and the signal block that
//! publishes them at output rows ([`block`]). A post-processing of the run: nothing here is
//! read by the right-hand side (docs/stress.md).
//!
//! # Sign convention (frame i of link i: x along the chord from joint i, y normal to it)
//! Cut link i at x. The part beyond x (the rest of link i and everything outboard) exerts on
//! the part before it a force `F` and a moment `M` about the section point (x, w(x)),
//! counter-clockwise positive. Then
//!
//! ```text
//! N = F·x̂ (tension positive),  V = −F·ŷ,  M  (positive: compression on the +y "top" fibre)
//! σ_top = N/A − M/W_top,  σ_bottom = N/A + M/W_bottom,  W = I/c
//! ```
//!
//! so that `M = EI w''` for the modal moment, and along the link (chord coordinates, q the
//! distributed load per length including gravity and −ρA a, μ the rotary-inertia couple
//! `−ρI (Ω̇ + θ̈)`):
//!
//! ```text
//! dN/dx = −q_x,   dV/dx = q_y,   dM/dx = V + w'(x) N − μ
//! ```
//!
//! (the `w'N` term because the section point sits on the deformed axis). "Top" is the +y
//! side of the link's frame: for a boom pointing right, the upper fibre.

pub mod block;
pub mod modal;
pub mod section;
pub mod summation;

pub use block::{ArmStress, StressInputs};
pub use section::CrossSection;
pub use summation::{SectionForces, SectionGrid};

#[cfg(test)]
mod tests;
