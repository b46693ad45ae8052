//! Rod buckling of a cylinder: Euler's load with the end fixity, the Johnson parabola for
//! short rods, and the check element `<cylinder>_rod_check` that publishes the rod force,
//! the critical load and the buckling margin.
//!
//! The rod is a solid round bar of diameter d: A = π d²/4, I = π d⁴/64, radius of gyration
//! r = √(I/A) = d/4. With the effective length K·L (L the column length, K from the end
//! fixity) and the slenderness λ = K·L/r:
//!
//! ```text
//! Euler      P_E = π² E I / (K L)²                                      (σ_E = π² E / λ²)
//! Johnson    P_J = A [σ_y − (σ_y / (2π))² λ² / E]     for λ < λ_t = π √(2E/σ_y)
//! ```
//!
//! At λ = λ_t both give σ = σ_y/2: the parabola meets Euler's hyperbola with the same value
//! (and slope), so the critical load is continuous in L.
//!
//! **Effective length factors** (the theoretical values of the ideal column, not the
//! design-code recommendations that round them up):
//!
//! | fixity | K | from |
//! |---|---|---|
//! | pinned-pinned | 1 | P = π²EI/L² |
//! | fixed-free (flag pole) | 2 | P = π²EI/(4L²) |
//! | fixed-pinned | π/β₁ = 0.699 155 … | β₁ = 4.493 409 457 909 064, the first positive root of tan β = β |
//! | fixed-fixed | 1/2 | P = 4π²EI/L² |
//!
//! **Column length.** The cylinder's check takes L as its current pin-to-pin length
//! l = l⁰ + s and the whole length with the rod's section: the barrel is stiffer than the
//! rod, so this underestimates the critical load of the stepped column (a conservative
//! margin), and it grows shorter-safer as the rod retracts.
//!
//! **No cost when unread.** [`RodCheck`] is a signal block with one stage writing signals
//! only; the right-hand side skips such stages unless an element taking part in dx/dt
//! reads them (none does), so the check is evaluated only when an output asks for it.

use bondgraph::kind::BuildError;
use bondgraph::{CausalRule, Element, Io, ParamError, Ports, SignalSpec};

/// β₁, the first positive root of tan β = β: the fixed–pinned column's P = β₁² EI / L².
pub const FIXED_PINNED_ROOT: f64 = 4.493_409_457_909_064;

/// Steel's Young's modulus, the default `E` of a cylinder's rod, Pa.
pub const STEEL_E: f64 = 210e9;

/// Above this margin (including a rod in tension or unloaded) the published
/// `buckling_margin` is this cap, so that every output stays finite.
pub const MARGIN_CAP: f64 = 1e6;

/// End conditions of the rod as a column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fixity {
    /// Both ends pinned (a cylinder on two clevises): K = 1.
    PinnedPinned,
    /// One end clamped, the other free (flag pole): K = 2.
    FixedFree,
    /// One end clamped, the other pinned: K = π/β₁ ≈ 0.6992 (see [`FIXED_PINNED_ROOT`]).
    FixedPinned,
    /// Both ends clamped: K = 0.5.
    FixedFixed,
}

impl Fixity {
    /// The names in model files, in the order of [`Fixity::ALL`].
    pub const NAMES: [&'static str; 4] =
        ["pinned-pinned", "fixed-free", "fixed-pinned", "fixed-fixed"];
    /// Every fixity.
    pub const ALL: [Fixity; 4] = [
        Fixity::PinnedPinned,
        Fixity::FixedFree,
        Fixity::FixedPinned,
        Fixity::FixedFixed,
    ];

    /// The effective length factor K (the effective length is K·L).
    #[must_use]
    pub fn k(self) -> f64 {
        match self {
            Fixity::PinnedPinned => 1.0,
            Fixity::FixedFree => 2.0,
            Fixity::FixedPinned => std::f64::consts::PI / FIXED_PINNED_ROOT,
            Fixity::FixedFixed => 0.5,
        }
    }

    /// The model-file name (`"pinned-pinned"`, …).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Fixity::PinnedPinned => Self::NAMES[0],
            Fixity::FixedFree => Self::NAMES[1],
            Fixity::FixedPinned => Self::NAMES[2],
            Fixity::FixedFixed => Self::NAMES[3],
        }
    }

    /// The fixity called `name`, or `None`.
    #[must_use]
    pub fn parse(name: &str) -> Option<Fixity> {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Self::ALL[i])
    }
}

/// Second moment of area of a solid round rod, π d⁴/64 (m⁴).
#[must_use]
pub fn rod_inertia(rod_d: f64) -> f64 {
    std::f64::consts::PI * rod_d.powi(4) / 64.0
}

/// Euler's critical load π² E I / (K L)² of a solid round rod (N).
#[must_use]
pub fn euler_load(e: f64, rod_d: f64, length: f64, fixity: Fixity) -> f64 {
    let kl = fixity.k() * length;
    std::f64::consts::PI.powi(2) * e * rod_inertia(rod_d) / (kl * kl)
}

/// The transition slenderness λ_t = π √(2E/σ_y) below which the Johnson parabola governs.
#[must_use]
pub fn transition_slenderness(e: f64, yield_strength: f64) -> f64 {
    std::f64::consts::PI * (2.0 * e / yield_strength).sqrt()
}

/// The critical (buckling) load of a solid round rod of diameter `rod_d` (m), Young's
/// modulus `e` (Pa) and column length `length` (m) with end conditions `fixity`, in N:
/// Euler's load, or — given the yield strength (Pa) and a slenderness K·L/r below
/// [`transition_slenderness`] — the Johnson parabola A [σ_y − (σ_y/2π)² λ²/E].
#[must_use]
pub fn buckling_load(
    e: f64,
    rod_d: f64,
    length: f64,
    fixity: Fixity,
    yield_strength: Option<f64>,
) -> f64 {
    if let Some(sy) = yield_strength {
        let lambda = fixity.k() * length / (rod_d / 4.0);
        if lambda < transition_slenderness(e, sy) {
            let area = std::f64::consts::PI * rod_d * rod_d / 4.0;
            let c = sy / (2.0 * std::f64::consts::PI);
            return area * (sy - c * c * lambda * lambda / e);
        }
    }
    euler_load(e, rod_d, length, fixity)
}

/// The margin against buckling, critical load / push force, capped at [`MARGIN_CAP`] (a
/// rod in tension or unloaded has no buckling risk; the cap keeps the output finite).
#[must_use]
pub fn margin(critical: f64, push: f64) -> f64 {
    if push * MARGIN_CAP > critical {
        critical / push
    } else {
        MARGIN_CAP
    }
}

/// A rod's buckling data: what a cylinder declares with `rod_d`, `E`, `yield`, `buckling`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rod {
    /// Rod diameter, m.
    pub d: f64,
    /// Young's modulus, Pa.
    pub e: f64,
    /// Yield strength, Pa, for the Johnson parabola (`None`: Euler only).
    pub yield_strength: Option<f64>,
    /// End conditions.
    pub fixity: Fixity,
}

impl Rod {
    /// Check the parameters; errors name the model-file keys.
    pub fn validate(&self) -> Result<(), ParamError> {
        ParamError::positive("rod_d", self.d)?;
        ParamError::positive("E", self.e)?;
        if let Some(s) = self.yield_strength {
            ParamError::positive("yield", s)?;
        }
        Ok(())
    }

    /// The critical load at column length `length` ([`buckling_load`]).
    #[must_use]
    pub fn critical_load(&self, length: f64) -> f64 {
        buckling_load(self.e, self.d, length, self.fixity, self.yield_strength)
    }
}

/// Parse a `buckling = "…"` word into a [`Fixity`], with the names in the error.
pub fn fixity_of(word: &str) -> Result<Fixity, BuildError> {
    Fixity::parse(word).ok_or_else(|| {
        BuildError::invalid("buckling", format!("unknown end fixity `{word}`"))
            .hint(format!("one of: {}", Fixity::NAMES.join(", ")))
    })
}

/// The check block of a cylinder: reads the force on the rod (N, push positive) and the
/// column length (m), publishes `force`, `p_cr` (critical load, N), `utilisation`
/// (force / p_cr; negative in tension) and `buckling_margin` (p_cr / force, [`margin`]).
/// It has no ports and writes signals only.
#[derive(Debug)]
pub struct RodCheck {
    rod: Rod,
    /// Signals read: the column length, then the force terms added (+) or subtracted (−).
    inputs: Vec<String>,
    /// Sign of each force input (after the length).
    signs: Vec<f64>,
}

impl RodCheck {
    /// A check reading the column length from signal `length` and the rod force as the sum
    /// of the signals `forces` with their signs (`(name, +1.0)` adds, `(name, −1.0)`
    /// subtracts).
    pub fn new(rod: Rod, length: &str, forces: &[(&str, f64)]) -> Result<Self, ParamError> {
        rod.validate()?;
        let mut inputs = vec![length.to_owned()];
        inputs.extend(forces.iter().map(|(n, _)| (*n).to_owned()));
        Ok(Self {
            rod,
            inputs,
            signs: forces.iter().map(|f| f.1).collect(),
        })
    }

    /// The rod data.
    #[must_use]
    pub fn rod(&self) -> Rod {
        self.rod
    }
}

impl Element for RodCheck {
    fn kind(&self) -> &str {
        "hydraulics.rod_check"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.inputs.iter().map(|n| SignalSpec::scalar(n)).collect()
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        ["force", "p_cr", "utilisation", "buckling_margin"]
            .into_iter()
            .map(SignalSpec::scalar)
            .collect()
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let length = io.u(0);
        let force: f64 = self
            .signs
            .iter()
            .enumerate()
            .map(|(i, s)| s * io.u(i + 1))
            .sum();
        let p_cr = self.rod.critical_load(length);
        io.set_y(0, 0, force);
        io.set_y(1, 0, p_cr);
        io.set_y(2, 0, force / p_cr);
        io.set_y(3, 0, margin(p_cr, force));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    const E: f64 = 210e9;
    const D: f64 = 0.06;

    #[test]
    fn euler_loads_of_the_four_end_conditions_match_the_closed_forms() {
        let i = PI * D.powi(4) / 64.0;
        for l in [0.5, 3.6056, 6.0, 12.0] {
            let pe = PI * PI * E * i / (l * l); // pinned-pinned
            let cases = [
                (Fixity::PinnedPinned, pe),
                (Fixity::FixedFree, pe / 4.0),
                (
                    Fixity::FixedPinned,
                    FIXED_PINNED_ROOT * FIXED_PINNED_ROOT * E * i / (l * l),
                ),
                (Fixity::FixedFixed, 4.0 * pe),
            ];
            for (f, want) in cases {
                let got = buckling_load(E, D, l, f, None);
                assert!(
                    ((got - want) / want).abs() < 1e-12,
                    "{f:?} L = {l}: {got} vs {want}"
                );
            }
        }
        // a hand value: d = 0.06, L = 6 m, pinned: I = 6.3617e-7 m⁴, P = 36.63 kN
        let p = euler_load(E, D, 6.0, Fixity::PinnedPinned);
        assert!((p - 36_626.0).abs() < 1.0, "{p}");
    }

    #[test]
    fn the_fixed_pinned_root_solves_tan_beta_equals_beta() {
        let b = FIXED_PINNED_ROOT;
        assert!((b.tan() - b).abs() < 1e-12 * b);
        assert!((Fixity::FixedPinned.k() - 0.699_155_6).abs() < 1e-7);
        assert!((1.0 / Fixity::FixedPinned.k().powi(2) - 2.045_8).abs() < 1e-4);
    }

    #[test]
    fn johnson_meets_euler_at_the_transition_and_caps_at_yield() {
        let sy = 355e6;
        let lt = transition_slenderness(E, sy);
        for f in Fixity::ALL {
            // the length whose slenderness K·L/r is the transition
            let l = lt * (D / 4.0) / f.k();
            let euler = euler_load(E, D, l, f);
            let area = PI * D * D / 4.0;
            assert!(((euler - area * sy / 2.0) / euler).abs() < 1e-12);
            let below = buckling_load(E, D, l * (1.0 - 1e-9), f, Some(sy));
            let above = buckling_load(E, D, l * (1.0 + 1e-9), f, Some(sy));
            assert!(((below - euler) / euler).abs() < 1e-8, "{below} vs {euler}");
            assert!(((above - euler) / euler).abs() < 1e-8, "{above} vs {euler}");
            // a short rod yields rather than buckles: P → A σ_y as L → 0
            let stub = buckling_load(E, D, 1e-6, f, Some(sy));
            assert!(((stub - area * sy) / (area * sy)).abs() < 1e-9);
            // Johnson lies below Euler's hyperbola for λ < λ_t
            let half = buckling_load(E, D, l / 2.0, f, Some(sy));
            assert!(half < euler_load(E, D, l / 2.0, f));
            assert!(half > euler);
        }
        // a long rod ignores the yield strength
        let l = 3.0 * lt * D / 4.0;
        assert_eq!(
            buckling_load(E, D, l, Fixity::PinnedPinned, Some(sy)).to_bits(),
            euler_load(E, D, l, Fixity::PinnedPinned).to_bits()
        );
    }

    #[test]
    fn margin_is_load_over_push_and_capped_in_tension() {
        assert!((margin(100e3, 25e3) - 4.0).abs() < 1e-15);
        assert!((margin(100e3, -5e3) - MARGIN_CAP).abs() < 1e-9);
        assert!((margin(100e3, 0.0) - MARGIN_CAP).abs() < 1e-9);
    }

    #[test]
    fn fixity_names_round_trip_and_unknown_names_list_the_choices() {
        for f in Fixity::ALL {
            assert_eq!(Fixity::parse(f.name()), Some(f));
        }
        let e = fixity_of("hinged").unwrap_err();
        assert_eq!(e.param.as_deref(), Some("buckling"));
        let hint = e.hint.unwrap_or_default();
        assert!(
            hint.contains("pinned-pinned") && hint.contains("fixed-fixed"),
            "{hint}"
        );
    }
}
