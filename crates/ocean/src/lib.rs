//! # bg-ocean: sea states and vessel motion for offshore models
//!
//! Pure Rust, no dependencies: everything a crane-on-a-vessel model needs from the sea,
//! evaluated allocation-free at any time with exact first and second time derivatives
//! (a moving base needs x, ẋ, ẍ). User documentation: `docs/sea-states.md`.
//!
//! - [`Spectrum`] (`spectrum.rs`): JONSWAP (Hs, Tp, γ, σa = 0.07, σb = 0.09, scaled so that
//!   4·√m0 = Hs) and Pierson–Moskowitz wave spectra S(ω) in m²·s/rad.
//! - [`Pcg32`] (`rng.rs`): the portable, documented random generator (PCG-XSH-RR 64/32):
//!   the same seed gives the same record on every machine.
//! - [`Harmonics`] (`harmonics.rs`): a sum of cosines Σ aₖ cos(ωₖ t + φₖ) with its exact
//!   derivatives: [`Harmonics::eval`] → (value, d/dt, d²/dt²).
//! - [`WaveRecord`] (`record.rs`): the random-phase superposition: equal-energy frequency
//!   bins of the record's own resolution 2π/duration, one component near each bin's
//!   centre (jittered at random), the count from duration and dt.
//! - [`Rao`] (`rao.rs`): response amplitude operators read from a documented CSV (heave,
//!   sway, roll amplitude and phase per frequency and heading), interpolated.
//! - [`VesselMotion`] (`vessel.rs`): heave, sway and roll at a point of the vessel (the
//!   crane pedestal) by small-angle kinematics, each a [`Harmonics`].
//! - [`analysis`]: the record's standard deviation, its Welch spectrum estimate and the
//!   spectral peak period (for checks and the `bg-sim sea` plot).

mod error;
mod harmonics;
mod record;
mod rng;
mod spectrum;
mod vessel;

pub mod analysis;
pub mod rao;

pub use error::OceanError;
pub use harmonics::{Component, Harmonics};
pub use rao::{Dof, Rao};
pub use record::{component_count, WaveRecord};
pub use rng::Pcg32;
pub use spectrum::Spectrum;
pub use vessel::{Point, VesselMotion};
