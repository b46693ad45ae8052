//! Screw algebra of section 2 of the paper, for planar motion embedded in 6-D exactly as the
//! paper writes it.
//!
//! * A **twist** is `t = [ω; v]` (eq. 4): angular velocity, then the linear velocity of the
//!   reference point. A **wrench** is `w = [f; n]` (eq. 14): force, then the moment about the
//!   reference point. Both are [`Screw`]s (6-vectors in Plücker coordinates).
//! * Planar motion in the x–y plane uses only `ω_z, v_x, v_y` (twist rows 2, 3, 4, zero-based)
//!   and `f_x, f_y, n_z` (wrench rows 0, 1, 5). The other rows stay exactly zero.
//! * A screw is changed to another reference point by [`ReferenceTransform`] `U` (eq. 9), to
//!   other coordinates by [`CoordinateTransform`] `R̄` (eq. 11), and both at once by
//!   [`ScrewTransform`] `V = R̄ U` (eq. 12), the adjoint map of SE(3).
//! * [`interchange`] `Π` (eq. 46) swaps the halves of a screw, so that `tᵀ Π w` is the power
//!   of wrench `w` on twist `t`.

mod interchange;
mod transform;
mod twist;
mod wrench;

pub use interchange::{interchange, power, swap};
pub use transform::{rot_z, rot_z_cs, CoordinateTransform, ReferenceTransform, ScrewTransform};
pub use twist::{joint_line, line_x, line_y, line_z, screw_n_x, screw_n_y, screw_n_z, twist};
pub use wrench::{reaction_basis, screw_basis, wrench};

/// A screw in Plücker coordinates: a twist `[ω; v]` or a wrench `[f; n]`.
pub type Screw = nalgebra::Vector6<f64>;
