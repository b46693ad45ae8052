//! Links: rigid bodies and flexible Euler–Bernoulli beams along a chord, with point masses.
//!
//! A link is described in its own frame i: the origin sits at the joint that carries it, the
//! x axis runs along its chord, and the cross-section at distance x sits at `(x, w(x))` with
//! `w(x) = Σ_k ψ_k(x) q_k^b` (section 3.1). Mass is distributed along the chord (mass per
//! length ρA, rotary inertia per length ρI as in eq. 40) and/or lumped in [`PointMass`]es on
//! the deformed axis. With no modes the link is rigid.
//!
//! ```text
//!   joint i ●━━━━━━━━━━━━━━━━━━━━━━━━━━━━━● joint i+1     (chord, x → L)
//!             ╲_________ w(x) ________╱                    (deformed axis)
//! ```

use std::sync::Arc;

use crate::mode_shape::{CantileverMode, ModeShape, SineMode};
use bondgraph::ParamError;

/// A point mass on the deformed axis of a link, at distance `x` along the chord.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointMass {
    /// Position along the chord (m), `0 ≤ x ≤ L`.
    pub x: f64,
    /// Mass (kg), ≥ 0.
    pub mass: f64,
    /// Rotary inertia about its own z axis (kg·m²), ≥ 0; it turns with the cross-section.
    pub inertia: f64,
}

/// One link of a planar serial manipulator.
#[derive(Clone, Debug)]
pub struct Link {
    length: f64,
    mass_per_length: f64,
    rotary_inertia_per_length: f64,
    bending_stiffness: f64,
    modes: Vec<Arc<dyn ModeShape>>,
    masses: Vec<PointMass>,
    geometric_stiffening: bool,
    free_end: bool,
    profile: Option<Arc<Profile>>,
}

/// Properties that vary along the chord (a tapered boom): each one, if given, as values
/// sampled at equally spaced x from 0 to L (at least two), interpolated linearly; otherwise
/// the link's uniform value. [`Link::with_profile`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Profile {
    /// EI(x) (N·m²).
    pub bending_stiffness: Option<Vec<f64>>,
    /// ρA(x) (kg/m).
    pub mass_per_length: Option<Vec<f64>>,
    /// ρI(x) (kg·m).
    pub rotary_inertia_per_length: Option<Vec<f64>>,
}

/// The linear interpolation at x ∈ [0, L] of values sampled at equally spaced points.
fn sampled(v: &[f64], length: f64, x: f64) -> f64 {
    let n = v.len() - 1;
    let t = (x / length).clamp(0.0, 1.0) * n as f64;
    let k = (t.floor() as usize).min(n - 1);
    let f = t - k as f64;
    v[k] + f * (v[k + 1] - v[k])
}

impl Link {
    /// A rigid uniform link: length `length` (m, > 0), mass per length `mass_per_length`
    /// (kg/m, ≥ 0).
    pub fn rigid(length: f64, mass_per_length: f64) -> Result<Self, ParamError> {
        Ok(Self {
            length: ParamError::positive("length", length)?,
            mass_per_length: ParamError::non_negative("mass_per_length", mass_per_length)?,
            rotary_inertia_per_length: 0.0,
            bending_stiffness: 0.0,
            modes: Vec::new(),
            masses: Vec::new(),
            geometric_stiffening: false,
            free_end: false,
            profile: None,
        })
    }

    /// A uniform Euler–Bernoulli beam of length `length`, Young's modulus `e` (Pa), density
    /// `rho` (kg/m³), cross-section area `a` (m²) and second moment of area `i` (m⁴): mass
    /// per length ρA, rotary inertia per length ρI (eq. 40), bending stiffness EI (eq. 50).
    /// Rigid until modes are added ([`with_sine_modes`](Self::with_sine_modes)).
    pub fn beam(length: f64, e: f64, rho: f64, a: f64, i: f64) -> Result<Self, ParamError> {
        let e = ParamError::positive("E", e)?;
        let rho = ParamError::positive("rho", rho)?;
        let a = ParamError::positive("A", a)?;
        let i = ParamError::positive("I", i)?;
        let mut link = Self::rigid(length, rho * a)?;
        link.rotary_inertia_per_length = rho * i;
        link.bending_stiffness = e * i;
        Ok(link)
    }

    /// The payload pendulum: a rigid massless link of length `length` with a point mass
    /// `mass` at its end (its frame's x axis points from the pivot to the payload).
    pub fn pendulum(length: f64, mass: f64) -> Result<Self, ParamError> {
        Self::rigid(length, 0.0)?.with_point_mass(PointMass {
            x: length,
            mass,
            inertia: 0.0,
        })
    }

    /// Set the rotary inertia per length ρI (kg·m).
    pub fn with_rotary_inertia(mut self, per_length: f64) -> Result<Self, ParamError> {
        self.rotary_inertia_per_length =
            ParamError::non_negative("rotary_inertia_per_length", per_length)?;
        Ok(self)
    }

    /// Set the bending stiffness EI (N·m²).
    pub fn with_bending_stiffness(mut self, ei: f64) -> Result<Self, ParamError> {
        self.bending_stiffness = ParamError::non_negative("EI", ei)?;
        Ok(self)
    }

    /// Add the first `n` hinged–hinged sine modes `sin(kπx/L)`, k = 1..n.
    pub fn with_sine_modes(self, n: u32) -> Result<Self, ParamError> {
        let l = self.length;
        (1..=n).try_fold(self, |link, k| {
            link.with_mode(Arc::new(SineMode::new(k, l)))
        })
    }

    /// Add the first `n` clamped–free modes ([`CantileverMode`]): the link must be the last
    /// of its arm (its end carries no joint; [`PlanarArm`](crate::PlanarArm) checks it), and
    /// its joint angle is then the angle of its root cross-section.
    pub fn with_cantilever_modes(mut self, n: u32) -> Result<Self, ParamError> {
        ParamError::positive("EI", self.bending_stiffness)?;
        let l = self.length;
        for k in 1..=n {
            self.modes.push(Arc::new(CantileverMode::new(k, l)));
        }
        self.free_end = n > 0;
        Ok(self)
    }

    /// Whether the link's modes move the end of its chord (cantilever modes): it must be the
    /// last link.
    #[must_use]
    pub fn has_free_end(&self) -> bool {
        self.free_end
    }

    /// Add an assumed mode. It must vanish at both ends of the chord (chord-to-chord joint
    /// angles), and the link must have a bending stiffness.
    pub fn with_mode(mut self, mode: Arc<dyn ModeShape>) -> Result<Self, ParamError> {
        ParamError::positive("EI", self.bending_stiffness)?;
        let scale = (0..=16)
            .map(|k| mode.value(self.length * f64::from(k) / 16.0).abs())
            .fold(0.0, f64::max)
            .max(1.0);
        for x in [0.0, self.length] {
            let v = mode.value(x);
            if !v.is_finite() || v.abs() > 1e-9 * scale {
                return Err(ParamError::shape(
                    "modes",
                    format!(
                        "a mode must vanish at both ends of the chord (chord-to-chord joint angles), but ψ({x}) = {v}"
                    ),
                ));
            }
        }
        self.modes.push(mode);
        Ok(self)
    }

    /// Keep (`true`) the second-order axial shortening of the bent link,
    /// `u(x) = −½∫₀ˣ (∂w/∂ξ)² dξ`, in the position of its material points, its pins and the
    /// end of its chord ([`geometric_stiffening`](crate::geometric_stiffening)). Off by default
    /// (the paper's beam); no effect on a rigid link.
    #[must_use]
    pub fn with_geometric_stiffening(mut self, on: bool) -> Self {
        self.geometric_stiffening = on;
        self
    }

    /// Let EI, ρA and/or ρI vary along the chord ([`Profile`]): the link's shape integrals
    /// are then computed by quadrature (at least 64 points), with the link's own assumed modes
    /// (sines, or cantilever modes) as a Ritz basis. Set the profile before adding modes.
    pub fn with_profile(mut self, profile: Profile) -> Result<Self, ParamError> {
        for (name, v, positive) in [
            ("EI(x)", &profile.bending_stiffness, true),
            ("rhoA(x)", &profile.mass_per_length, false),
            ("rhoI(x)", &profile.rotary_inertia_per_length, false),
        ] {
            if let Some(v) = v {
                if v.len() < 2 {
                    return Err(ParamError::shape(
                        name,
                        "needs at least two samples (at x = 0 and x = L, equally spaced)",
                    ));
                }
                for &x in v {
                    if positive {
                        ParamError::positive(name, x)?;
                    } else {
                        ParamError::non_negative(name, x)?;
                    }
                }
            }
        }
        let mean = |v: &[f64]| {
            let n = (v.len() - 1) as f64;
            (v.iter().sum::<f64>() - 0.5 * (v[0] + v[v.len() - 1])) / n
        };
        if let Some(v) = &profile.bending_stiffness {
            self.bending_stiffness = mean(v);
        }
        if let Some(v) = &profile.mass_per_length {
            self.mass_per_length = mean(v);
        }
        if let Some(v) = &profile.rotary_inertia_per_length {
            self.rotary_inertia_per_length = mean(v);
        }
        self.profile = Some(Arc::new(profile));
        Ok(self)
    }

    /// Whether EI, ρA and ρI are the same all along the chord.
    #[must_use]
    pub fn is_uniform(&self) -> bool {
        self.profile.is_none()
    }
    /// ρA at x (kg/m).
    #[must_use]
    pub fn mass_per_length_at(&self, x: f64) -> f64 {
        match self
            .profile
            .as_deref()
            .and_then(|p| p.mass_per_length.as_deref())
        {
            Some(v) => sampled(v, self.length, x),
            None => self.mass_per_length,
        }
    }
    /// ρI at x (kg·m).
    #[must_use]
    pub fn rotary_inertia_per_length_at(&self, x: f64) -> f64 {
        match self
            .profile
            .as_deref()
            .and_then(|p| p.rotary_inertia_per_length.as_deref())
        {
            Some(v) => sampled(v, self.length, x),
            None => self.rotary_inertia_per_length,
        }
    }
    /// EI at x (N·m²).
    #[must_use]
    pub fn bending_stiffness_at(&self, x: f64) -> f64 {
        match self
            .profile
            .as_deref()
            .and_then(|p| p.bending_stiffness.as_deref())
        {
            Some(v) => sampled(v, self.length, x),
            None => self.bending_stiffness,
        }
    }

    /// Add a point mass on the deformed axis.
    pub fn with_point_mass(mut self, m: PointMass) -> Result<Self, ParamError> {
        if !(m.x.is_finite() && (0.0..=self.length).contains(&m.x)) {
            return Err(ParamError::invalid(
                "point_mass.x",
                m.x,
                "within the link, 0 <= x <= L",
            ));
        }
        ParamError::non_negative("point_mass.mass", m.mass)?;
        ParamError::non_negative("point_mass.inertia", m.inertia)?;
        self.masses.push(m);
        Ok(self)
    }

    /// Chord length L (m).
    #[must_use]
    pub fn length(&self) -> f64 {
        self.length
    }
    /// Mass per length ρA (kg/m); its mean along the chord with a [`Profile`].
    #[must_use]
    pub fn mass_per_length(&self) -> f64 {
        self.mass_per_length
    }
    /// Rotary inertia per length ρI (kg·m).
    #[must_use]
    pub fn rotary_inertia_per_length(&self) -> f64 {
        self.rotary_inertia_per_length
    }
    /// Bending stiffness EI (N·m²).
    #[must_use]
    pub fn bending_stiffness(&self) -> f64 {
        self.bending_stiffness
    }
    /// The assumed modes.
    #[must_use]
    pub fn modes(&self) -> &[Arc<dyn ModeShape>] {
        &self.modes
    }
    /// The point masses.
    #[must_use]
    pub fn point_masses(&self) -> &[PointMass] {
        &self.masses
    }
    /// Whether the axial shortening of the bent link is kept (and it has modes).
    #[must_use]
    pub fn geometric_stiffening(&self) -> bool {
        self.geometric_stiffening && !self.modes.is_empty()
    }
    /// Whether the link has no modes.
    #[must_use]
    pub fn is_rigid(&self) -> bool {
        self.modes.is_empty()
    }
    /// Whether the link has distributed mass or rotary inertia to integrate.
    #[must_use]
    pub fn has_distributed_mass(&self) -> bool {
        self.mass_per_length > 0.0 || self.rotary_inertia_per_length > 0.0
    }
    /// Total mass (kg).
    #[must_use]
    pub fn mass(&self) -> f64 {
        self.mass_per_length * self.length + self.masses.iter().map(|m| m.mass).sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constructors_reject_bad_values() {
        assert!(Link::rigid(0.0, 1.0).is_err());
        assert!(Link::rigid(1.0, -1.0).is_err());
        assert!(Link::beam(1.0, 210e9, 7850.0, 0.0, 1e-4).is_err());
        assert!(Link::pendulum(6.0, f64::NAN).is_err());
        assert!(Link::rigid(1.0, 1.0).unwrap().with_sine_modes(1).is_err()); // no EI
        let l = Link::rigid(2.0, 1.0).unwrap();
        assert!(l
            .with_point_mass(PointMass {
                x: 2.5,
                mass: 1.0,
                inertia: 0.0
            })
            .is_err());
    }

    #[test]
    fn modes_must_vanish_at_the_chord_ends() {
        #[derive(Debug)]
        struct Cantilever;
        impl ModeShape for Cantilever {
            fn value(&self, x: f64) -> f64 {
                x * x
            }
            fn slope(&self, x: f64) -> f64 {
                2.0 * x
            }
            fn curvature(&self, _: f64) -> f64 {
                2.0
            }
        }
        let beam = Link::beam(10.0, 210e9, 7850.0, 0.0264, 5.89e-4).unwrap();
        assert!(beam.clone().with_mode(Arc::new(Cantilever)).is_err());
        let b = beam.with_sine_modes(3).unwrap();
        assert_eq!(b.modes().len(), 3);
        assert!((b.mass() - 7850.0 * 0.0264 * 10.0).abs() < 1e-9);
    }
}
