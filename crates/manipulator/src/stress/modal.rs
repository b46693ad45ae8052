//! The modal bending moment `M = EI(x) w''(x) = EI(x) Σ_k ψ_k''(x) q_k` of the assumed modes
//! ([`SectionForces::m_modal`](crate::stress::SectionForces::m_modal), computed beside the
//! summed one by [`section_forces_into`](crate::ArmKinematics::section_forces_into)).
//!
//! It is the moment of the strain energy of eq. 50 alone: it leaves out the internal
//! damping, and with few modes it converges slowly where point loads (pins) put kinks in the
//! exact moment — a sine series of a function with a kink converges as 1/k², its second
//! derivative's as 1/k⁰ locally. Hinged–hinged sine modes give w'' = 0 at both chord ends,
//! where a joint torque or an eccentric load can make the summed moment non-zero. The
//! outputs and `bg-sim stress` therefore use the summed moment; the modal one is published
//! as `M_modal` for comparison (docs/stress.md shows both).

/// `EI · Σ_k ψ_k'' q_k` from the mode curvatures `curvature` (ψ_k'' at x) and the modal
/// coordinates `qb`.
#[must_use]
pub fn modal_moment(ei: f64, curvature: &[f64], qb: &[f64]) -> f64 {
    ei * curvature.iter().zip(qb).map(|(c, q)| c * q).sum::<f64>()
}
