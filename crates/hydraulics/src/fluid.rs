//! The oil's compliance as a function of pressure, for [`Chamber`](crate::Chamber): entrained
//! air and cavitation. Both are options; without them the chamber's law is the constant-β
//! one (eq. 28) and its arithmetic is untouched.
//!
//! Pressures p are gauge (Pa), as everywhere in this crate; the laws below need the
//! absolute pressure p_abs = p + p_atm.
//!
//! ## Entrained air ([`EntrainedAir`])
//!
//! Undissolved air as bubbles, a volume fraction ε of the mixture at p_atm, compressed
//! polytropically (V_air ∝ p_abs^(−1/n)); the oil itself has the constant modulus β. With
//! r(p) = a·(p_atm/p_abs)^(1/n), a = ε/(1 − ε) the air-to-oil volume ratio at p_atm, the
//! mixture's modulus is (Jelali & Kroll, *Hydraulic Servo-systems*, 2003, sect. 2.3.3, the
//! classical form also in Merritt, *Hydraulic Control Systems*, 1967; reviewed by Gholizadeh,
//! Burton & Schoenau, "Fluid bulk modulus: a literature survey", 2011):
//!
//! ```text
//! β_eff(p) = β · (1 + r) / (1 + r·β/(n·p_abs))        1/β_eff = (1/β + r/(n·p_abs)) / (1 + r)
//! ```
//!
//! It tends to β as p → ∞ (r → 0, r/p_abs → 0) and to n·p_abs (the air's own polytropic
//! modulus) as p_abs → 0. The oil's own volume change is neglected in r (|p|/β ≪ 1).
//!
//! ## Cavitation ([`Cavitation`])
//!
//! When the absolute pressure approaches the vapour pressure p_v, vapour and released gas
//! form a cavity that takes up the volume the oil leaves. We represent it by a cavity volume
//! that is a function of the pressure alone (our regularisation, not a published law):
//!
//! ```text
//! x = (p_abs − p_v)/p_c,        V_cav(p) = V_ref · e^(−x) / x          (x > 0)
//! C_cav(p) = −dV_cav/dp = (V_ref/p_c) · e^(−x)·(1/x + 1/x²)
//! ```
//!
//! with p_c the width of the cavitation band (Pa) and V_ref the chamber's reference volume.
//! The chamber's compliance is then V·(1/β_eff) + C_cav, i.e. the effective modulus drops
//! steeply within about 10–15 p_c of p_v (for β = 1.5 GPa, V = V_ref; at 20 p_c the cavity's
//! compliance is below 1e-4 of the oil's). Because V_cav → ∞ as p_abs → p_v (like V_ref·p_c/δ
//! with δ = p_abs − p_v), a finite outflow can never bring the pressure to p_v: the
//! pressure stays above it, and the volume balance holds exactly,
//!
//! ```text
//! ∫Q_in dt = ΔV + ∫ V/β_eff(p) dp − ΔV_cav
//! ```
//!
//! (Q_in the flow into the chamber from outside, V its volume from the stroke). The cavity
//! collapses as the pressure recovers (V_cav is a function of p only, so it is reversible).
//!
//! The chamber's pressure law is written with the *gain* g = 1/(V/β_eff + C_cav):
//! dp/dt = g·f_in. Multiplying numerator and denominator by x², g = x²/(x²·V/β_eff +
//! (V_ref/p_c)·e^(−x)·(x + 1)), which is finite for x > 0 and vanishes like x² at p_v; for
//! x ≤ 0 (the cavity would be infinite) g = 0, so the law is C¹ across p_v. This matters for
//! implicit solvers: a step's stage equation p₁ = p₀ + h·g(p₁)·f_in has no solution below
//! p_v when p₀ is above it, so a long step taken while the oil decompresses linearly cannot
//! jump over the band (a continuation of g below p_v that stayed positive let Radau step
//! from 0.2 MPa straight to −0.2 MPa gauge in a test).

use bondgraph::kind::{BuildError, ParamDecl, Params};
use bondgraph::ParamError;

/// Entrained (undissolved) air: volume fraction `fraction` ε of the mixture at the
/// atmospheric pressure `p_atm` (Pa, absolute), compressed with polytropic exponent `n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EntrainedAir {
    /// a = ε/(1 − ε): air-to-oil volume ratio at p_atm.
    a: f64,
    p_atm: f64,
    n: f64,
}

impl EntrainedAir {
    /// ε in [0, 1), `p_atm` > 0 (Pa, absolute), `n` ≥ 1 (1 isothermal … 1.4 adiabatic).
    pub fn new(fraction: f64, p_atm: f64, n: f64) -> Result<Self, ParamError> {
        if !(fraction.is_finite() && (0.0..1.0).contains(&fraction)) {
            return Err(ParamError::OutOfRange {
                param: "air_fraction".into(),
                value: fraction,
                requirement: "in [0, 1)",
            });
        }
        ParamError::positive("p_atm", p_atm)?;
        if !(n.is_finite() && n >= 1.0) {
            return Err(ParamError::OutOfRange {
                param: "n_air".into(),
                value: n,
                requirement: "finite and >= 1 (1 isothermal, 1.4 adiabatic)",
            });
        }
        Ok(Self {
            a: fraction / (1.0 - fraction),
            p_atm,
            n,
        })
    }
}

/// Cavitation below the absolute vapour pressure `p_vapour` (Pa), over a band of width
/// `p_band` (Pa), with a cavity scaled by `v_ref` (m³).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cavitation {
    p_vapour: f64,
    p_band: f64,
    v_ref: f64,
}

impl Cavitation {
    /// The same with another reference volume.
    pub(crate) fn with_v_ref(self, v_ref: f64) -> Self {
        Self { v_ref, ..self }
    }

    /// `p_vapour` ≥ 0 (absolute), `p_band` > 0, `v_ref` > 0.
    pub fn new(p_vapour: f64, p_band: f64, v_ref: f64) -> Result<Self, ParamError> {
        ParamError::non_negative("p_vapour", p_vapour)?;
        ParamError::positive("p_cav_band", p_band)?;
        ParamError::positive("v_ref", v_ref)?;
        Ok(Self {
            p_vapour,
            p_band,
            v_ref,
        })
    }
}

/// The fluid options of a chamber as a model file gives them (all off by default): what
/// [`Chamber::with_fluid`](crate::Chamber::with_fluid) and the cylinder's chambers take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluidOptions {
    /// Atmospheric pressure, Pa absolute (`p_atm`, default 101 325).
    pub p_atm: f64,
    /// Entrained air: (ε, n), the volume fraction of free air at p_atm (`air_fraction`, in
    /// [0, 1)) and its polytropic exponent (`n_air`, default 1.4).
    pub air: Option<(f64, f64)>,
    /// Cavitation: (p_v, p_c), the vapour pressure (`p_vapour`, Pa absolute, default 1e3)
    /// and the width of the cavitation band (`p_cav_band`, Pa, default 1e3).
    pub cavitation: Option<(f64, f64)>,
}

impl Default for FluidOptions {
    fn default() -> Self {
        Self {
            p_atm: 101_325.0,
            air: None,
            cavitation: None,
        }
    }
}

impl FluidOptions {
    /// Whether any option is on.
    #[must_use]
    pub fn any(&self) -> bool {
        self.air.is_some() || self.cavitation.is_some()
    }
}

/// Atmospheric pressure (`p_atm`), declared once for the chamber and the cylinder.
pub const P_ATM: ParamDecl = ParamDecl::number(
    "p_atm",
    "Pa",
    "atmospheric pressure, absolute (gauge → absolute; with air or cavitation)",
)
.positive()
.default(101_325.0);
/// Volume fraction of free air at p_atm (`air_fraction`).
pub const AIR_FRACTION: ParamDecl = ParamDecl::number(
    "air_fraction",
    "1",
    "entrained air: volume fraction ε of free air at p_atm, in [0, 1)",
)
.non_negative()
.optional("no entrained air");
/// Polytropic exponent of the air (`n_air`).
pub const N_AIR: ParamDecl = ParamDecl::number(
    "n_air",
    "1",
    "polytropic exponent of the entrained air, ≥ 1 (1 isothermal, 1.4 adiabatic)",
)
.positive()
.default(1.4);
/// Whether cavitation is represented (`cavitation`).
pub const CAVITATION: ParamDecl = ParamDecl::flag(
    "cavitation",
    false,
    "represent cavitation: a cavity near p_vapour keeps the pressure above it",
);
/// Vapour pressure (`p_vapour`).
pub const P_VAPOUR: ParamDecl = ParamDecl::number(
    "p_vapour",
    "Pa",
    "vapour pressure, absolute (with cavitation)",
)
.non_negative()
.default(1e3);
/// Width of the cavitation band (`p_cav_band`).
pub const P_CAV_BAND: ParamDecl = ParamDecl::number(
    "p_cav_band",
    "Pa",
    "width p_c of the cavitation band (with cavitation)",
)
.positive()
.default(1e3);

/// The fluid options a chamber or cylinder declares ([`P_ATM`], [`AIR_FRACTION`],
/// [`N_AIR`], [`CAVITATION`], [`P_VAPOUR`], [`P_CAV_BAND`]); the keys of an option that is
/// off are refused rather than ignored.
pub fn options(p: &dyn Params) -> Result<FluidOptions, BuildError> {
    let mut o = FluidOptions {
        p_atm: p.number("p_atm")?,
        ..FluidOptions::default()
    };
    if let Some(fraction) = p.optional("air_fraction")? {
        o.air = Some((fraction, p.number("n_air")?));
    } else if p.has("n_air") {
        return Err(BuildError::conflict(
            "n_air",
            "`n_air` needs entrained air: give `air_fraction` too",
        ));
    }
    if p.flag("cavitation")? {
        o.cavitation = Some((p.number("p_vapour")?, p.number("p_cav_band")?));
    } else if let Some(k) = ["p_vapour", "p_cav_band"].into_iter().find(|k| p.has(k)) {
        return Err(BuildError::conflict(
            k,
            format!("`{k}` is a cavitation parameter, but cavitation is off"),
        )
        .hint("add `cavitation = true` to represent cavitation"));
    }
    if !o.any() && p.has("p_atm") {
        return Err(BuildError::conflict(
            "p_atm",
            "`p_atm` is used only with entrained air or cavitation",
        )
        .hint("add `air_fraction = …` or `cavitation = true`, or remove `p_atm`"));
    }
    Ok(o)
}

/// The absolute pressure below which entrained air is evaluated at this floor (Pa): only a
/// solver's overshoot reaches it, since β_eff → 0 as p_abs → 0.
const P_ABS_FLOOR: f64 = 1.0;

/// The oil of a chamber: bulk modulus β (Pa), with optional entrained air and cavitation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fluid {
    /// Bulk modulus of the oil, Pa.
    pub beta: f64,
    /// Atmospheric pressure, Pa absolute (gauge → absolute).
    pub p_atm: f64,
    /// Entrained air, if any.
    pub air: Option<EntrainedAir>,
    /// Cavitation, if represented.
    pub cavitation: Option<Cavitation>,
}

impl Fluid {
    /// Compressibility 1/β_eff(p) (1/Pa) and its derivative in p, at gauge pressure `p`.
    #[must_use]
    pub fn compressibility(&self, p: f64) -> (f64, f64) {
        let Some(air) = self.air else {
            return (1.0 / self.beta, 0.0);
        };
        let raw = p + air.p_atm;
        let (u, du) = if raw > P_ABS_FLOOR {
            (raw, 1.0)
        } else {
            (P_ABS_FLOOR, 0.0)
        };
        let n = air.n;
        let r = air.a * (air.p_atm / u).powf(1.0 / n);
        let dr = -r / (n * u);
        let num = 1.0 / self.beta + r / (n * u);
        let dnum = dr / (n * u) - r / (n * u * u);
        let den = 1.0 + r;
        let k = num / den;
        let dk = (dnum * den - num * dr) / (den * den);
        (k, dk * du)
    }

    /// Effective bulk modulus β_eff(p) (Pa) of the oil with its entrained air.
    #[must_use]
    pub fn bulk_modulus(&self, p: f64) -> f64 {
        1.0 / self.compressibility(p).0
    }

    /// The gain g = 1/(V/β_eff(p) + C_cav(p)) of dp/dt = g·f_in at gauge pressure `p` and
    /// volume `v` (m³), with ∂g/∂p and ∂g/∂V.
    #[must_use]
    pub fn gain(&self, p: f64, v: f64) -> (f64, f64, f64) {
        let (k, dk) = self.compressibility(p);
        let Some(c) = self.cavitation else {
            let g = 1.0 / (v * k);
            return (g, -g * dk / k, -g / v);
        };
        // g = x²/(x²·V·k + (V_ref/p_c)·e^(−x)·(x + 1)) for x > 0, 0 below
        let x = (p + self.p_atm - c.p_vapour) / c.p_band;
        if x <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        let w = c.v_ref / c.p_band;
        let e = (-x).exp();
        let x2 = x * x;
        let den = x2 * v * k + w * e * (x + 1.0);
        let g = x2 / den;
        // ∂den/∂x = 2x·V·k + x²·V·(dk/dp)·p_c + w·e·(−(x + 1) + 1), the last = −w·e·x
        let dden_dx = 2.0 * x * v * k + x2 * v * dk * c.p_band - w * e * x;
        let dg_dx = (2.0 * x * den - x2 * dden_dx) / (den * den);
        let dg_dv = -x2 * x2 * k / (den * den);
        (g, dg_dx / c.p_band, dg_dv)
    }

    /// Cavity volume V_cav(p) (m³) and its derivative in p; zero without cavitation.
    /// At or below p_v (only an overshoot) it is evaluated just above p_v.
    #[must_use]
    pub fn cavity(&self, p: f64) -> (f64, f64) {
        let Some(c) = self.cavitation else {
            return (0.0, 0.0);
        };
        let x = ((p + self.p_atm - c.p_vapour) / c.p_band).max(1e-12);
        let e = (-x).exp();
        let v = c.v_ref * e / x;
        (v, -c.v_ref / c.p_band * e * (1.0 / x + 1.0 / (x * x)))
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact zeros are meant exactly
mod tests {
    use super::*;

    fn oil(air: Option<EntrainedAir>, cav: Option<Cavitation>) -> Fluid {
        Fluid {
            beta: 1.5e9,
            p_atm: 1.013e5,
            air,
            cavitation: cav,
        }
    }

    #[test]
    fn entrained_air_matches_the_closed_form_and_tends_to_beta() {
        let (eps, pa, n, beta) = (0.01, 1.013e5, 1.4, 1.5e9);
        let f = oil(Some(EntrainedAir::new(eps, pa, n).unwrap()), None);
        for p in [0.0, 1e5, 1e6, 1e7, 3e7] {
            // the mixture's definition: β_eff = −V·dp/dV with V = V_oil + V_air,
            // V_oil = V_o0 (oil stiffness β), V_air = V_a0·(p_atm/p_abs)^(1/n)
            let u: f64 = p + pa;
            let (vo, va) = (1.0 - eps, eps * (pa / u).powf(1.0 / n));
            let expected = (vo + va) / (vo / beta + va / (n * u));
            let got = f.bulk_modulus(p);
            assert!(
                (got / expected - 1.0).abs() < 1e-12,
                "{p}: {got} vs {expected}"
            );
        }
        // low pressure: the air dominates; high pressure: the oil
        assert!(f.bulk_modulus(0.0) < 0.02 * beta);
        let high = f.bulk_modulus(1e9);
        assert!((high / beta - 1.0).abs() < 1e-3, "{high}");
        assert!(f.bulk_modulus(3e7) < f.bulk_modulus(1e8));
        // ε = 0 is the plain oil
        let none = oil(Some(EntrainedAir::new(0.0, pa, n).unwrap()), None);
        assert!((none.bulk_modulus(1e6) / beta - 1.0).abs() < 1e-15);
    }

    #[test]
    fn compressibility_derivative_matches_differences() {
        let f = oil(Some(EntrainedAir::new(0.02, 1.013e5, 1.2).unwrap()), None);
        for p in [-5e4_f64, 0.0, 2e5, 5e6] {
            let h = 1e-4 * (p.abs() + 1e5);
            let fd = (f.compressibility(p + h).0 - f.compressibility(p - h).0) / (2.0 * h);
            let (_, dk) = f.compressibility(p);
            assert!((dk - fd).abs() <= 1e-6 * fd.abs(), "{p}: {dk} vs {fd}");
        }
    }

    #[test]
    fn gain_and_cavity_are_consistent() {
        let cav = Cavitation::new(2e3, 1e3, 1e-3).unwrap();
        let f = oil(
            Some(EntrainedAir::new(0.001, 1.013e5, 1.4).unwrap()),
            Some(cav),
        );
        let v = 1.2e-3;
        for p in [-9.9e4_f64, -9.5e4, -8e4, 0.0, 1e6] {
            let (g, gp, gv) = f.gain(p, v);
            // g = 1/(V/β_eff + C_cav), C_cav = −dV_cav/dp
            let (k, _) = f.compressibility(p);
            let (_, dcav) = f.cavity(p);
            let expected = 1.0 / (v * k - dcav);
            assert!((g / expected - 1.0).abs() < 1e-10, "{p}: {g} vs {expected}");
            let hp = 1e-6 * (p.abs() + 1e3);
            let fd_p = (f.gain(p + hp, v).0 - f.gain(p - hp, v).0) / (2.0 * hp);
            let fd_v = (f.gain(p, v * (1.0 + 1e-6)).0 - f.gain(p, v * (1.0 - 1e-6)).0) / (2e-6 * v);
            assert!(
                (gp - fd_p).abs() <= 1e-5 * fd_p.abs().max(1e-30),
                "{p}: {gp} vs {fd_p}"
            );
            assert!(
                (gv - fd_v).abs() <= 1e-5 * fd_v.abs(),
                "{p}: {gv} vs {fd_v}"
            );
            // the cavity's derivative
            let fd_c = (f.cavity(p + hp).0 - f.cavity(p - hp).0) / (2.0 * hp);
            assert!((dcav - fd_c).abs() <= 1e-5 * fd_c.abs().max(1e-300), "{p}");
        }
        // the gain vanishes at p_v like (p_abs − p_v)², and below it
        let pv = 2e3 - 1.013e5;
        assert_eq!(f.gain(pv, v).0, 0.0);
        assert_eq!(f.gain(pv - 10.0, v), (0.0, 0.0, 0.0));
        let (a, b) = (f.gain(pv + 1e-3, v).0, f.gain(pv + 2e-3, v).0);
        assert!((b / a - 4.0).abs() < 1e-4, "{}", b / a);
        // far above p_v the cavity does not change the law (relative 1e-12 at 1 MPa)
        let plain = oil(f.air, None);
        assert!((f.gain(1e6, v).0 / plain.gain(1e6, v).0 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(EntrainedAir::new(1.0, 1e5, 1.4).is_err());
        assert!(EntrainedAir::new(-0.1, 1e5, 1.4).is_err());
        assert!(EntrainedAir::new(0.1, 0.0, 1.4).is_err());
        assert!(EntrainedAir::new(0.1, 1e5, 0.9).is_err());
        assert!(Cavitation::new(-1.0, 1e3, 1e-3).is_err());
        assert!(Cavitation::new(1e3, 0.0, 1e-3).is_err());
        assert!(Cavitation::new(1e3, 1e3, 0.0).is_err());
    }
}
