//! # bg-fatigue: rainflow counting, S–N curves and Miner's damage
//!
//! Pure functions on a sampled history (a stress in Pa, or a force as a stand-in), no
//! dependence on the model loader or the CLI:
//!
//! - [`rainflow`]: the turning points of a history ([`reversals`], with a hysteresis gate)
//!   and the three-point rainflow count of ASTM E1049-85 §5.4.4 ([`count`]), the residue as
//!   half cycles (the standard) or closed by repeating the history ([`Residue`]).
//! - [`sn`]: S–N curves [`SnCurve`] of the EN 1993-1-9 / DNV-RP-C203 shape (slope m₁ to the
//!   knee, m₂ after it, an optional cut-off) with the named presets ([`SnCurve::preset`],
//!   [`PRESETS`]) and an explicit curve (`m=3,range=71e6,cycles=2e6`, [`SnCurve::parse`]).
//! - [`miner`]: Palmgren–Miner damage D = Σ nᵢ/Nᵢ of counted cycles with a stress
//!   concentration factor ([`damage`]).
//!
//! ```
//! use bg_fatigue::{count, damage, reversals, Residue, SnCurve};
//! let history = [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0]; // ASTM E1049 Fig. 6
//! let cycles = count(&reversals(&history, 0.0), Residue::Half);
//! let n: f64 = cycles.iter().map(|c| c.count).sum();
//! assert!((n - 4.0).abs() < 1e-15); // 1 full cycle + 6 half cycles
//! let curve = SnCurve::preset("ec3-71").unwrap();
//! let scaled: Vec<_> = cycles.iter().map(|c| c.scaled(20e6)).collect(); // 1 unit = 20 MPa
//! assert!(damage(&scaled, &curve, 1.0) > 0.0);
//! ```

pub mod miner;
pub mod rainflow;
pub mod sn;

pub use miner::damage;
pub use rainflow::{count, reversals, Cycle, Residue};
pub use sn::{Preset, SnCurve, SnError, PRESETS};
