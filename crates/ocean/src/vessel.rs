//! The motion of a point of the vessel (the crane pedestal) in a sea, from the wave record
//! and the RAOs.
//!
//! Each component k of the elevation, aₖ·cos(ωₖt + φₖ), drives each degree of freedom
//! linearly: heave_k = aₖ|H(ωₖ, β)|·cos(ωₖt + φₖ + θ(ωₖ, β)), the same for sway and roll.
//! A point P at (x, y, z) from the motion reference point in the vessel's axes (x to the
//! bow, y to port, z up) moves, for small angles (displacement = translation + θ × r with
//! only roll φ about x tabulated, pitch and yaw taken as zero):
//!
//! - heave at P = heave + y·φ,
//! - sway at P  = sway − z·φ,
//! - roll at P  = φ.
//!
//! These are linear, so they are formed per component on the complex transfer functions
//! (H_heave + y·H_roll, H_sway − z·H_roll) and every degree of freedom is again a
//! [`Harmonics`] with exact derivatives. The vessel's motion does not feel the crane.

use crate::harmonics::{Component, Harmonics};
use crate::{Dof, Rao, WaveRecord};

/// A point of the vessel, from the RAO's motion reference point, in the vessel's axes [m].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Point {
    /// Towards the bow.
    pub x: f64,
    /// Towards port.
    pub y: f64,
    /// Up.
    pub z: f64,
}

/// Heave, sway and roll of a point of the vessel (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct VesselMotion {
    elevation: Harmonics,
    heave: Harmonics,
    sway: Harmonics,
    roll: Harmonics,
}

impl VesselMotion {
    /// The motion at `point` of a vessel with `rao` in the waves `record` arriving at
    /// `heading` [deg].
    #[must_use]
    pub fn new(record: &WaveRecord, rao: &Rao, heading: f64, point: Point) -> Self {
        let comps = record.harmonics().components();
        let polar = |(a, p): (f64, f64)| (a * p.cos(), a * p.sin());
        let mut heave = Vec::with_capacity(comps.len());
        let mut sway = Vec::with_capacity(comps.len());
        let mut roll = Vec::with_capacity(comps.len());
        for c in comps {
            let h = polar(rao.at(Dof::Heave, c.omega, heading));
            let s = polar(rao.at(Dof::Sway, c.omega, heading));
            let r = polar(rao.at(Dof::Roll, c.omega, heading));
            let hp = (h.0 + point.y * r.0, h.1 + point.y * r.1);
            let sp = (s.0 - point.z * r.0, s.1 - point.z * r.1);
            for (list, (re, im)) in [(&mut heave, hp), (&mut sway, sp), (&mut roll, r)] {
                list.push(Component {
                    amplitude: c.amplitude * re.hypot(im),
                    omega: c.omega,
                    phase: c.phase + im.atan2(re),
                });
            }
        }
        Self {
            elevation: record.harmonics().clone(),
            heave: Harmonics::new(heave),
            sway: Harmonics::new(sway),
            roll: Harmonics::new(roll),
        }
    }
    /// The time series of `dof`.
    #[must_use]
    pub fn series(&self, dof: Dof) -> &Harmonics {
        match dof {
            Dof::Elevation => &self.elevation,
            Dof::Heave => &self.heave,
            Dof::Sway => &self.sway,
            Dof::Roll => &self.roll,
        }
    }
    /// (value, d/dt, d²/dt²) of `dof` at `t` (m or rad), exact, allocation-free.
    #[must_use]
    pub fn eval(&self, dof: Dof, t: f64) -> (f64, f64, f64) {
        self.series(dof).eval(t)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;

    const TABLE: &str = "heading_deg,omega_rad_s,heave_amp_m_per_m,heave_phase_deg,sway_amp_m_per_m,sway_phase_deg,roll_amp_deg_per_m,roll_phase_deg\n\
90,0.4,1.0,0,0.9,90,1.0,-80\n\
90,0.7,0.8,-25,0.7,95,4.0,-120\n\
90,1.2,0.1,-120,0.2,130,0.5,170\n";

    /// Fit a·cos(ωt) + b·sin(ωt) to samples over whole periods: amplitude and phase.
    fn fit(f: impl Fn(f64) -> f64, omega: f64) -> (f64, f64) {
        let period = 2.0 * std::f64::consts::PI / omega;
        let n = 4000;
        let (mut c, mut s) = (0.0, 0.0);
        for k in 0..n {
            let t = period * f64::from(k) / f64::from(n);
            c += f(t) * (omega * t).cos();
            s += f(t) * (omega * t).sin();
        }
        let (a, b) = (2.0 * c / f64::from(n), 2.0 * s / f64::from(n));
        (a.hypot(b), (-b).atan2(a))
    }

    /// The "done when": a regular wave through an RAO gives the RAO's amplitude and
    /// phase to 1e-6 (at a tabulated and at an interpolated frequency).
    #[test]
    fn a_regular_wave_through_the_rao_gives_its_amplitude_and_phase() {
        let rao = Rao::parse(TABLE).unwrap();
        for omega in [0.7, 0.95] {
            let (a, phi) = (1.3, 0.4);
            let wave = WaveRecord::regular(a, omega, phi);
            let m = VesselMotion::new(&wave, &rao, 90.0, Point::default());
            for dof in [Dof::Heave, Dof::Sway, Dof::Roll] {
                let (amp, phase) = rao.at(dof, omega, 90.0);
                let (ga, gp) = fit(|t| m.eval(dof, t).0, omega);
                assert!((ga - a * amp).abs() < 1e-6 * a * amp.max(1.0), "{dof:?} ω {omega}: {ga} vs {}", a * amp);
                let dp = ((gp - (phi + phase)) + 3.0 * std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI;
                assert!(dp.abs() < 1e-6, "{dof:?} ω {omega}: phase off by {dp}");
            }
        }
        // the tabulated values themselves at ω = 0.7: heave 0.8 ∠ −25°
        let (amp, phase) = rao.at(Dof::Heave, 0.7, 90.0);
        assert!((amp - 0.8).abs() < 1e-15 && (phase.to_degrees() + 25.0).abs() < 1e-12);
    }

    #[test]
    fn a_point_off_the_centre_line_heaves_with_roll_and_sways_with_it_below() {
        let rao = Rao::parse(TABLE).unwrap();
        let wave = WaveRecord::regular(1.0, 0.7, 0.0);
        let o = VesselMotion::new(&wave, &rao, 90.0, Point::default());
        let p = Point { x: 5.0, y: 8.0, z: 12.0 };
        let m = VesselMotion::new(&wave, &rao, 90.0, p);
        for t in [0.0, 1.7, 4.2] {
            let (h, hd, hdd) = m.eval(Dof::Heave, t);
            let (r, rd, rdd) = o.eval(Dof::Roll, t);
            let (h0, h0d, h0dd) = o.eval(Dof::Heave, t);
            assert!((h - (h0 + 8.0 * r)).abs() < 1e-12);
            assert!((hd - (h0d + 8.0 * rd)).abs() < 1e-12);
            assert!((hdd - (h0dd + 8.0 * rdd)).abs() < 1e-12);
            let (s, _, _) = m.eval(Dof::Sway, t);
            assert!((s - (o.eval(Dof::Sway, t).0 - 12.0 * r)).abs() < 1e-12);
            assert_eq!(m.eval(Dof::Roll, t), o.eval(Dof::Roll, t));
        }
    }
}
