//! Wave spectra S(ω) [m²·s/rad] of a sea state given by its significant wave height Hs and
//! peak period Tp (ωp = 2π/Tp).
//!
//! Pierson–Moskowitz in its Hs–Tp form (as DNV-RP-C205 writes it):
//!
//! S_PM(ω) = 5/16 · Hs² · ωp⁴ · ω⁻⁵ · exp(−5/4 · (ωp/ω)⁴),
//!
//! whose zeroth moment m0 = ∫S dω is Hs²/16 exactly (substitute u = (ωp/ω)⁴), so 4·√m0 = Hs.
//!
//! JONSWAP: the PM shape times the peak enhancement γ^r, r = exp(−(ω − ωp)² / (2σ²ωp²)),
//! σ = σa = 0.07 for ω ≤ ωp and σb = 0.09 above:
//!
//! S_J(ω) = A_γ · S_PM(ω) · γ^r.
//!
//! The enhancement adds energy, so A_γ < 1 brings m0 back to Hs²/16. DNV's closed-form
//! A_γ = 1 − 0.287·ln γ is an approximation (about 1 % off at γ = 3.3); here A_γ is computed
//! once, when the spectrum is made, as (Hs²/16) / ∫ S_PM·γ^r dω, the integral by composite
//! Simpson in u = ωp/ω over (0, 4] (ω from ωp/4 to ∞: the spectrum below ωp/4 is below
//! e^(−320) of its peak) with 4000 panels: 4·√m0 = Hs to about 1e-12.

use std::f64::consts::PI;

use crate::OceanError;

/// A wave spectrum (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Spectrum {
    /// Pierson–Moskowitz: a fully developed sea.
    PiersonMoskowitz {
        /// Significant wave height Hs [m].
        hs: f64,
        /// Peak period Tp [s].
        tp: f64,
    },
    /// JONSWAP: a fetch-limited sea, peak enhancement γ.
    Jonswap {
        /// Significant wave height Hs [m].
        hs: f64,
        /// Peak period Tp [s].
        tp: f64,
        /// Peak enhancement factor γ (3.3 for the mean JONSWAP sea; 1 is PM).
        gamma: f64,
        /// The normalisation A_γ, computed by [`Spectrum::jonswap`].
        scale: f64,
    },
}

/// Peak width below the peak, σa.
pub const SIGMA_A: f64 = 0.07;
/// Peak width above the peak, σb.
pub const SIGMA_B: f64 = 0.09;

fn check(name: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Result<(), OceanError> {
    if v.is_finite() && v > lo && v <= hi {
        Ok(())
    } else {
        Err(OceanError::new(format!("{name} = {v} {unit} is outside ({lo}, {hi}]"))
            .hint(format!("{name} is a positive number of {unit}")))
    }
}

impl Spectrum {
    /// Pierson–Moskowitz with significant height `hs` [m] and peak period `tp` [s].
    ///
    /// # Errors
    /// Hs not in (0, 40] m or Tp not in (0, 60] s.
    pub fn pierson_moskowitz(hs: f64, tp: f64) -> Result<Self, OceanError> {
        check("Hs", hs, 0.0, 40.0, "m")?;
        check("Tp", tp, 0.0, 60.0, "s")?;
        Ok(Self::PiersonMoskowitz { hs, tp })
    }
    /// JONSWAP with `hs` [m], `tp` [s] and peak enhancement `gamma` (1 ≤ γ ≤ 10), scaled so
    /// that 4·√m0 = Hs (see the module documentation).
    ///
    /// # Errors
    /// Hs, Tp as for PM; γ not in [1, 10].
    pub fn jonswap(hs: f64, tp: f64, gamma: f64) -> Result<Self, OceanError> {
        check("Hs", hs, 0.0, 40.0, "m")?;
        check("Tp", tp, 0.0, 60.0, "s")?;
        if !(gamma.is_finite() && (1.0..=10.0).contains(&gamma)) {
            return Err(OceanError::new(format!("gamma = {gamma} is outside [1, 10]"))
                .hint("the peak enhancement γ is 3.3 for the mean JONSWAP sea, 1 for Pierson–Moskowitz"));
        }
        let raw = Self::Jonswap {
            hs,
            tp,
            gamma,
            scale: 1.0,
        };
        let m0 = raw.moment0();
        Ok(Self::Jonswap {
            hs,
            tp,
            gamma,
            scale: hs * hs / 16.0 / m0,
        })
    }
    /// Significant wave height Hs [m].
    #[must_use]
    pub fn hs(&self) -> f64 {
        match *self {
            Self::PiersonMoskowitz { hs, .. } | Self::Jonswap { hs, .. } => hs,
        }
    }
    /// Peak period Tp [s].
    #[must_use]
    pub fn tp(&self) -> f64 {
        match *self {
            Self::PiersonMoskowitz { tp, .. } | Self::Jonswap { tp, .. } => tp,
        }
    }
    /// Peak frequency ωp = 2π/Tp [rad/s].
    #[must_use]
    pub fn omega_p(&self) -> f64 {
        2.0 * PI / self.tp()
    }
    /// S(ω) [m²·s/rad]; 0 for ω ≤ 0.
    #[must_use]
    pub fn density(&self, omega: f64) -> f64 {
        if omega <= 0.0 {
            return 0.0;
        }
        let wp = self.omega_p();
        let hs = self.hs();
        let r = wp / omega;
        let r4 = r * r * r * r;
        let pm = 5.0 / 16.0 * hs * hs * r4 / omega * (-1.25 * r4).exp();
        match *self {
            Self::PiersonMoskowitz { .. } => pm,
            Self::Jonswap { gamma, scale, .. } => {
                let sigma = if omega <= wp { SIGMA_A } else { SIGMA_B };
                let x = (omega - wp) / (sigma * wp);
                scale * pm * gamma.powf((-0.5 * x * x).exp())
            }
        }
    }
    /// m0 = ∫₀^∞ S dω by composite Simpson in u = ωp/ω ∈ (0, 4] (dω = ωp/u² du).
    #[must_use]
    pub fn moment0(&self) -> f64 {
        let wp = self.omega_p();
        let n = 4000;
        let h = 4.0 / f64::from(n);
        let f = |u: f64| {
            if u <= 0.0 {
                0.0 // S ~ ω⁻⁵ = (u/ωp)⁵: S·ωp/u² → 0
            } else {
                self.density(wp / u) * wp / (u * u)
            }
        };
        let mut s = f(0.0) + f(4.0);
        for k in 1..n {
            let w = if k % 2 == 1 { 4.0 } else { 2.0 };
            s += w * f(f64::from(k) * h);
        }
        s * h / 3.0
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp, clippy::panic)]
    use super::*;

    #[test]
    fn pm_and_jonswap_hold_four_root_m0_equal_hs() {
        let pm = Spectrum::pierson_moskowitz(2.5, 9.0).unwrap();
        assert!((4.0 * pm.moment0().sqrt() - 2.5).abs() < 1e-10);
        for gamma in [1.0, 2.0, 3.3, 7.0] {
            let j = Spectrum::jonswap(2.5, 9.0, gamma).unwrap();
            assert!((4.0 * j.moment0().sqrt() - 2.5).abs() < 1e-10, "γ = {gamma}");
        }
    }

    #[test]
    fn jonswap_scale_is_close_to_the_dnv_approximation_and_gamma_one_is_pm() {
        let j = Spectrum::jonswap(2.5, 9.0, 3.3).unwrap();
        let Spectrum::Jonswap { scale, .. } = j else {
            panic!("not JONSWAP")
        };
        let dnv = 1.0 - 0.287 * 3.3f64.ln();
        assert!((scale / dnv - 1.0).abs() < 0.02, "A = {scale}, DNV {dnv}");
        let j1 = Spectrum::jonswap(2.5, 9.0, 1.0).unwrap();
        let pm = Spectrum::pierson_moskowitz(2.5, 9.0).unwrap();
        for w in [0.3, 0.6, 0.7, 1.0, 2.0] {
            assert!((j1.density(w) / pm.density(w) - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn the_spectrum_peaks_at_omega_p() {
        for s in [
            Spectrum::pierson_moskowitz(2.5, 9.0).unwrap(),
            Spectrum::jonswap(2.5, 9.0, 3.3).unwrap(),
        ] {
            let wp = s.omega_p();
            assert!(s.density(wp) > s.density(wp * 0.999));
            assert!(s.density(wp) > s.density(wp * 1.001));
        }
    }

    #[test]
    fn bad_numbers_are_refused() {
        assert!(Spectrum::jonswap(-1.0, 9.0, 3.3).is_err());
        assert!(Spectrum::jonswap(2.0, f64::NAN, 3.3).is_err());
        assert!(Spectrum::jonswap(2.0, 9.0, 0.5).is_err());
    }
}
