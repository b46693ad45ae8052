//! # bg-mechanical: mechanical drive components as bond-graph elements
//!
//! Kinds in the namespace `mechanical.`, registered like `hydraulics.` (`bg_sim::registry`
//! adds [`KINDS`]). User documentation: `docs/sea-states.md` (the winch section).
//!
//! ## Elements (one file each: law, causality, tests)
//! - [`Winch`] (`mechanical.winch`): a drum of radius r and inertia J behind a gear of
//!   ratio n, with viscous damping and a regularised brake; a shaft port (torque, speed)
//!   for a motor, a wire port (tension, pay-out speed), the paid-out length as a state.

mod kinds;
mod winch;

pub use kinds::KINDS;
pub use winch::Winch;
