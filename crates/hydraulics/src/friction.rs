//! Friction `hydraulics.friction`: regularised Coulomb + Stribeck + viscous friction, a
//! one-port `R` on a mechanical velocity — a cylinder's seals (N against m/s) or a shaft's
//! bearings (N·m against rad/s).
//!
//! The static Stribeck curve (Armstrong-Hélouvry, Dupont & Canudas de Wit, "A survey of
//! models, analysis tools and compensation methods for the control of machines with
//! friction", Automatica 30(7), 1994; Olsson, Åström, Canudas de Wit, Gäfvert & Lischinsky,
//! "Friction models and friction compensation", European Journal of Control 4(3), 1998,
//! eq. 5 with δ = 2), with the sign function regularised by a hyperbolic tangent:
//!
//! ```text
//! F(v) = (F_c + (F_s − F_c)·exp(−(v/v_s)²))·tanh(v/v_tanh) + b·v
//! ```
//!
//! F_c is the Coulomb level, F_s the breakaway (static) level, v_s the Stribeck velocity, b
//! the viscous coefficient. **Regularisation:** `tanh(v/v_tanh)` stands for `sign(v)`; it is
//! within 1 % of it for |v| ≥ 2.7·v_tanh and within 4e-9 for |v| ≥ 10·v_tanh, and it makes
//! F smooth (C^∞) with a finite slope `F_s/v_tanh + b` at v = 0. There is no stiction: at
//! rest the element is a steep viscous damper, so a body under a force below F_s creeps at
//! about v_tanh·F/F_s. Choose v_tanh well below v_s and below the speeds of interest.
//!
//! F is odd (F(−v) = −F(v), exactly in floating point), and for F_c, F_s ≥ 0, b ≥ 0 the
//! dissipated power F·v is ≥ 0: the bracket lies between F_c and F_s, and tanh(v)·v ≥ 0.
//!
//! Causality: resistance only (the velocity comes in, the force goes out); the law is not
//! invertible where the Stribeck curve falls. Bond it *from* the 1-junction of the moving
//! body (its flow in is then the body's velocity).

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, Slot,
};

/// The static friction law `F(v)`: Coulomb level `f_c`, breakaway level `f_s`, Stribeck
/// velocity `v_s`, regularisation velocity `v_tanh`, viscous coefficient `b` (units: effort
/// and flow of the bond, e.g. N and m/s, or N·m and rad/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionLaw {
    f_c: f64,
    f_s: f64,
    v_s: f64,
    v_tanh: f64,
    b: f64,
}

impl FrictionLaw {
    /// A friction law; `f_c`, `f_s`, `b` finite and ≥ 0, `v_s`, `v_tanh` finite and > 0.
    pub fn new(f_c: f64, f_s: f64, v_s: f64, v_tanh: f64, b: f64) -> Result<Self, ParamError> {
        ParamError::non_negative("f_c", f_c)?;
        ParamError::non_negative("f_s", f_s)?;
        ParamError::positive("v_s", v_s)?;
        ParamError::positive("v_tanh", v_tanh)?;
        ParamError::non_negative("b", b)?;
        Ok(Self {
            f_c,
            f_s,
            v_s,
            v_tanh,
            b,
        })
    }

    /// No friction at all (F ≡ 0).
    #[must_use]
    pub fn none() -> Self {
        Self {
            f_c: 0.0,
            f_s: 0.0,
            v_s: 1.0,
            v_tanh: 1.0,
            b: 0.0,
        }
    }

    /// Coulomb (regularised over `v_tanh`) and viscous friction, no Stribeck peak (F_s = F_c).
    pub fn coulomb_viscous(f_c: f64, v_tanh: f64, b: f64) -> Result<Self, ParamError> {
        Self::new(f_c, f_c, 1.0, v_tanh, b)
    }

    /// The friction force (or torque) at velocity `v`.
    #[must_use]
    pub fn force(&self, v: f64) -> f64 {
        let level = self.f_c + (self.f_s - self.f_c) * (-(v / self.v_s).powi(2)).exp();
        level * (v / self.v_tanh).tanh() + self.b * v
    }

    /// dF/dv, exact:
    /// `−2v/v_s²·(F_s − F_c)·e^{−(v/v_s)²}·tanh(v/v_t) + level·(1 − tanh²(v/v_t))/v_t + b`.
    #[must_use]
    pub fn slope(&self, v: f64) -> f64 {
        let e = (-(v / self.v_s).powi(2)).exp();
        let level = self.f_c + (self.f_s - self.f_c) * e;
        let th = (v / self.v_tanh).tanh();
        let d_level = -2.0 * v / (self.v_s * self.v_s) * (self.f_s - self.f_c) * e;
        d_level * th + level * (1.0 - th * th) / self.v_tanh + self.b
    }
}

/// One-port friction element (`hydraulics.friction`): e = F(f_in) with [`FrictionLaw`].
#[derive(Debug)]
pub struct Friction {
    law: FrictionLaw,
}

impl Friction {
    /// A friction element with the given law.
    #[must_use]
    pub fn new(law: FrictionLaw) -> Self {
        Self { law }
    }

    /// The law.
    #[must_use]
    pub fn law(&self) -> &FrictionLaw {
        &self.law
    }
}

impl Element for Friction {
    fn kind(&self) -> &str {
        "hydraulics.friction"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::EffortOut]])
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let f = self.law.force(io.f_in(0, 0));
        io.set_e(0, 0, f);
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let d = self.law.slope(io.f_in(0, 0));
        jac.set(jac.row(Slot::Effort(0), 0), jac.flow_col(0, 0), d);
        true
    }
}

/// A friction law from a model's parameters, under the keys `keys` =
/// [Coulomb, breakaway, Stribeck velocity, regularisation velocity, viscous] (`f_c`, `f_s`,
/// `v_s`, `v_tanh`, `b` for the element; `t_c`, `t_s`, `omega_s`, `omega_tanh`, `b` for a
/// machine's friction torque). The breakaway level defaults to the Coulomb level; a
/// breakaway level needs its Stribeck velocity.
pub fn law_of(p: &dyn Params, keys: [&str; 5]) -> Result<FrictionLaw, BuildError> {
    let [k_c, k_s, k_vs, k_vt, k_b] = keys;
    let f_c = p.number(k_c)?;
    let (f_s, v_s) = match p.optional(k_s)? {
        Some(f_s) => match p.optional(k_vs)? {
            Some(v_s) => (f_s, v_s),
            None => {
                return Err(BuildError::missing(
                    k_vs,
                    format!("a breakaway level `{k_s}` needs the Stribeck velocity `{k_vs}`"),
                )
                .hint(format!(
                    "add `{k_vs} = …` (the speed over which the friction falls from `{k_s}` to `{k_c}`), or drop `{k_s}`"
                )))
            }
        },
        None => {
            if p.has(k_vs) {
                return Err(BuildError::conflict(
                    k_vs,
                    format!("`{k_vs}` without a breakaway level `{k_s}` has no effect"),
                )
                .hint(format!("add `{k_s} = …` or drop `{k_vs}`")));
            }
            (f_c, 1.0)
        }
    };
    FrictionLaw::new(f_c, f_s, v_s, p.number(k_vt)?, p.number(k_b)?).map_err(|e| {
        // name the model's key, not the law's
        let ParamError::OutOfRange { param, .. } = &e else {
            return e.into();
        };
        let i = ["f_c", "f_s", "v_s", "v_tanh", "b"]
            .iter()
            .position(|k| k == param)
            .unwrap_or(4);
        BuildError::invalid(keys[i], e.to_string().replace(param.as_str(), keys[i]))
    })
}

/// Kind `hydraulics.friction`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.friction",
    "friction on a velocity: F = (F_c + (F_s − F_c)·exp(−(v/v_s)²))·tanh(v/v_tanh) + b·v",
    &[
        ParamDecl::number("f_c", "", "Coulomb level (N, or N·m on a shaft)")
            .non_negative()
            .default(0.0),
        ParamDecl::number("f_s", "", "breakaway level (N or N·m)")
            .non_negative()
            .optional("f_c: no Stribeck peak"),
        ParamDecl::number("v_s", "", "Stribeck velocity (m/s or rad/s)")
            .positive()
            .optional("needed with f_s"),
        ParamDecl::number(
            "v_tanh",
            "",
            "regularisation velocity of sign(v) (m/s or rad/s)",
        )
        .positive()
        .default(1e-3),
        ParamDecl::number("b", "", "viscous coefficient (N·s/m or N·m·s/rad)")
            .non_negative()
            .default(0.0),
    ],
    |p| {
        let law = law_of(p, ["f_c", "f_s", "v_s", "v_tanh", "b"])?;
        Ok(Box::new(Friction::new(law)))
    },
)
.example("f_c = 800, f_s = 1200, v_s = 0.01, v_tanh = 1e-4, b = 2000");

#[cfg(test)]
mod tests {
    use super::*;

    /// Seal friction of a cylinder: 800 N Coulomb, 1200 N breakaway, v_s = 10 mm/s,
    /// v_tanh = 0.1 mm/s, 2000 N·s/m viscous.
    fn seal() -> FrictionLaw {
        FrictionLaw::new(800.0, 1200.0, 0.01, 1e-4, 2000.0).unwrap()
    }

    fn speeds() -> impl Iterator<Item = f64> {
        (-400i32..=400).map(|k| 1e-5 * f64::from(k) * f64::from(k.abs()).sqrt())
    }

    #[test]
    fn odd_and_dissipative() {
        for law in [
            seal(),
            FrictionLaw::new(1200.0, 800.0, 0.01, 1e-4, 0.0).unwrap(),
        ] {
            for v in speeds() {
                let f = law.force(v);
                assert_eq!(law.force(-v).to_bits(), (-f).to_bits(), "v = {v}");
                assert!(f * v >= 0.0, "v = {v}: F·v = {:e}", f * v);
            }
        }
        assert_eq!(seal().force(0.0).to_bits(), 0.0f64.to_bits());
    }

    #[test]
    fn far_from_the_stribeck_velocity_it_is_coulomb_plus_viscous() {
        // v ≥ 100·v_s: exp(−10⁴) underflows to 0 and tanh(v/v_tanh) rounds to 1.
        let law = seal();
        for v in [1.0, 2.5, 10.0] {
            let expected = 800.0 + 2000.0 * v;
            assert!((law.force(v) - expected).abs() <= 1e-12 * expected, "{v}");
            assert!((law.force(-v) + expected).abs() <= 1e-12 * expected, "{v}");
        }
        // At v = 3·v_s: F_c + (F_s − F_c)·e⁻⁹ + b·v, tanh(300) = 1.
        let v = 0.03;
        let expected = 800.0 + 400.0 * (-9.0f64).exp() + 2000.0 * v;
        assert!((law.force(v) - expected).abs() <= 1e-12 * expected);
        // Just past the regularisation the breakaway level is reached: F(10·v_tanh) is
        // F_s·(1 − 4e-9) up to the Stribeck drop (v/v_s)² = 1e-2 and the viscous term.
        let v = 1e-3;
        let expected = (800.0 + 400.0 * (-0.01f64).exp()) * (10.0f64).tanh() + 2000.0 * v;
        assert!((law.force(v) - expected).abs() <= 1e-12 * expected);
        assert!((law.force(v) - 1200.0).abs() < 6.0);
    }

    #[test]
    fn slope_matches_central_differences() {
        let law = seal();
        for v in speeds().chain([0.0, 1e-4, -3e-3, 0.01, 0.5]) {
            let h = 1e-6 * v.abs().max(1e-5);
            let fd = (law.force(v + h) - law.force(v - h)) / (2.0 * h);
            let d = law.slope(v);
            // central differences err by h²·F‴/6; relative to the largest slope (F_s/v_tanh)
            assert!(
                (d - fd).abs() <= 1e-6 * (fd.abs() + 2000.0),
                "v = {v}: {d:e} vs {fd:e}"
            );
        }
        assert!((law.slope(0.0) - (1200.0 / 1e-4 + 2000.0)).abs() < 1e-6);
    }

    #[test]
    fn element_partials_match_central_differences() {
        use bondgraph::check_partials;
        let f = Friction::new(seal());
        for sign in [1.0, -1.0] {
            for v in [-0.2, -2e-4, 3e-5, 0.012, 1.0] {
                let ports = [(1, sign, PortCausality::EffortOut)];
                assert_eq!(check_partials(&f, &ports, &[0.0, v]), Ok(1), "{v}");
            }
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(FrictionLaw::new(-1.0, 0.0, 1.0, 1.0, 0.0).is_err());
        assert!(FrictionLaw::new(1.0, f64::NAN, 1.0, 1.0, 0.0).is_err());
        assert!(FrictionLaw::new(1.0, 1.0, 0.0, 1.0, 0.0).is_err());
        assert!(FrictionLaw::new(1.0, 1.0, 1.0, 0.0, 0.0).is_err());
        assert!(FrictionLaw::new(1.0, 1.0, 1.0, 1.0, -2.0).is_err());
        assert!(FrictionLaw::coulomb_viscous(5.0, 1e-3, 0.1).is_ok());
        assert_eq!(FrictionLaw::none().force(3.0).to_bits(), 0.0f64.to_bits());
    }
}
