//! Cylinder `hydraulics.cylinder`: a valve-controlled double-acting cylinder as one component
//! (the paper's Fig. 5, bonds i1–i12), a composite that expands into its members.
//!
//! ```text
//!  valve.A ─⇀ jp (0) ─⇀ chamber_p (C: P_p)          members, named <instance>_<local>:
//!             jp ─⇀ piston.p                         valve, jp, jr, chamber_p, chamber_r,
//!             jp ─⇀ leak.a, leak.b ─⇀ jr  (r_int)    piston, rod, [leak, leak_p, leak_r,
//!             jp ─⇀ leak_p            (r_ext)         end_stop]
//!  valve.B ─⇀ jr (0) ─⇀ chamber_r (C: P_r)
//!             jr ─⇀ piston.r,  jr ─⇀ leak_r (r_ext)
//!  piston.mech ─⇀ rod (1) ─⇀ end_stop     exposed ports: mech = rod, A = jp, B = jr
//! ```
//!
//! The exposed port `mech` carries the net rod force F_c − F_stop (N; positive pushes the pins
//! apart) as effort and the length rate dl/dt (m/s) as flow; bond it *from* the cylinder to
//! the mechanism (`"cyl.mech -> load"`). The valve reads the spool stroke `x_v` (a signal
//! expression). Without a valve (`valve: None`) the lines are driven through the exposed
//! ports `A` and `B`.
//!
//! Chamber pressures start from [`InitialPressures`]; [`hold_pressures`] is the scene's
//! static initialisation rule.
//!
//! **Rod check.** A member `rod_check` ([`RodCheck`], [`crate::buckling`]) publishes the rod
//! force (`force`: F_c − F_stop, push positive), its critical load (`p_cr`: Euler with the
//! current pin-to-pin length l and the end fixity `buckling`, the Johnson parabola for a
//! short rod when `yield` is given), `utilisation` = force/p_cr and `buckling_margin` =
//! p_cr/force. It writes signals only, so a run evaluates it only when an output reads it.

use bondgraph::kind::{
    member_name, BuildError, Change, KindDecl, ParamDecl, Params, Simplification,
};
use bondgraph::{BondGraph, Composite, Error, OneJunction, Param, ParamError, ZeroJunction};

use crate::{fluid, orifice};

use crate::buckling::{self, Fixity, Rod, RodCheck};
use crate::{Chamber, EndStop, FluidOptions, Leakage, Piston, Side, Valve};

/// The chamber pressures (P_p, P_r) that hold force `force` (N, positive pushing the pins
/// apart) with the less loaded chamber at `p_pre` (docs/knuckle-boom.md, "Initial state"):
/// for F ≥ 0, P_r = p_pre and P_p = (F + A_r·p_pre)/A_p; for F < 0, P_p = p_pre and
/// P_r = (A_p·p_pre − F)/A_r. Then A_p·P_p − A_r·P_r = F exactly (up to rounding).
#[must_use]
pub fn hold_pressures(force: f64, a_p: f64, a_r: f64, p_pre: f64) -> (f64, f64) {
    if force >= 0.0 {
        ((force + a_r * p_pre) / a_p, p_pre)
    } else {
        (p_pre, (a_p * p_pre - force) / a_r)
    }
}

/// How the chamber pressures start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InitialPressures {
    /// Given pressures P_p, P_r (Pa).
    Given {
        /// Piston side, Pa.
        p_p: f64,
        /// Rod side, Pa.
        p_r: f64,
    },
    /// The pressures that hold `force` (N) with the less loaded chamber at `p_pre` (Pa):
    /// [`hold_pressures`].
    Hold {
        /// Force to hold, N.
        force: f64,
        /// Pressure of the less loaded chamber, Pa.
        p_pre: f64,
    },
}

/// The cylinder's directional valve (see [`Valve`]).
#[derive(Debug)]
pub struct ValveSpec {
    /// Orifice coefficient α at full opening, m³/(s·√Pa).
    pub alpha: f64,
    /// Spool stroke x_v (dimensionless, clamped to [−1, 1]), usually a signal.
    pub x_v: Param,
    /// Supply pressure, Pa.
    pub p_s: f64,
    /// Transition pressure of the square-root regularisation, Pa (0: the paper's law).
    pub p_tr: f64,
}

/// The cylinder's end stop (see [`EndStop`]), acting past s = 0 and s = s_max.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndStopSpec {
    /// Stiffness, N/m.
    pub k: f64,
    /// Damping, N·s/m.
    pub c: f64,
    /// Contact width over which the damping sets in, m.
    pub width: f64,
}

/// A double-acting cylinder with its chambers, piston, leakage, optional valve and end stop.
/// Lengths in m, areas in m², pressures in Pa.
#[derive(Debug)]
pub struct Cylinder {
    /// Piston area A_p (`a_p`).
    pub a_p: f64,
    /// Rod-side (annulus) area A_r (`a_r`).
    pub a_r: f64,
    /// Length at s = 0, fully retracted (`l0`); the published length is l = l0 + s.
    pub l0: f64,
    /// Piston-side chamber length at s = 0 (`l_p0`): V_p = A_p·(l_p0 + s).
    pub l_p0: f64,
    /// Rod-side chamber length at s = 0 (`l_r0`): V_r = A_r·(l_r0 − s).
    pub l_r0: f64,
    /// Usable stroke (`s_max`), ≤ `l_r0`.
    pub s_max: f64,
    /// Initial stroke (`s0`).
    pub s0: f64,
    /// Bulk modulus β (`beta`).
    pub beta: f64,
    /// Smallest chamber volume, m³ (`v_min`); default 1e-3 of each chamber's dead volume.
    pub v_min: Option<f64>,
    /// Tank pressure P_T (`p_t`).
    pub p_t: f64,
    /// Initial chamber pressures.
    pub initial: InitialPressures,
    /// The valve, or `None` to drive the lines through ports `A` and `B`.
    pub valve: Option<ValveSpec>,
    /// Internal leakage resistance R_l, Pa·s/m³ (`r_int`), if any.
    pub r_int: Option<f64>,
    /// External leakage resistance of each chamber to tank, Pa·s/m³ (`r_ext`), if any.
    pub r_ext: Option<f64>,
    /// End stop, if any; without one, leaving [0, s_max] stops the run with an error.
    pub end_stop: Option<EndStopSpec>,
    /// Entrained air and cavitation in both chambers (default: off, constant β).
    pub fluid: FluidOptions,
    /// The rod as a column for the buckling check; `None` (from [`Cylinder::new`]): a steel
    /// rod of the diameter the areas give, √(4(A_p − A_r)/π), pinned at both ends — if
    /// A_p > A_r (a double-rod cylinder with equal areas then has no check).
    pub rod: Option<Rod>,
}

/// Where the exposed ports of a cylinder added with [`Cylinder::add_to`] are: element names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CylinderPorts {
    /// The rod's 1-junction (port `mech`).
    pub mech: String,
    /// The piston-side line's 0-junction (port `A`).
    pub a: String,
    /// The rod-side line's 0-junction (port `B`).
    pub b: String,
    /// The piston (its state `s`, its signal `l`).
    pub piston: String,
}

impl Cylinder {
    /// A cylinder with the given geometry and bulk modulus, at s0 = 0, tank at 0 Pa, both
    /// chambers at 0 Pa, no valve, no leakage, no end stop. Set the public fields for more.
    #[must_use]
    pub fn new(a_p: f64, a_r: f64, l_p0: f64, l_r0: f64, s_max: f64, beta: f64) -> Self {
        Self {
            a_p,
            a_r,
            l0: 0.0,
            l_p0,
            l_r0,
            s_max,
            s0: 0.0,
            beta,
            v_min: None,
            p_t: 0.0,
            initial: InitialPressures::Given { p_p: 0.0, p_r: 0.0 },
            valve: None,
            r_int: None,
            r_ext: None,
            end_stop: None,
            fluid: FluidOptions::default(),
            rod: None,
        }
    }

    /// The rod diameter the areas give, √(4(A_p − A_r)/π) (m), if A_p > A_r.
    #[must_use]
    pub fn rod_diameter(&self) -> Option<f64> {
        (self.a_p > self.a_r).then(|| (4.0 * (self.a_p - self.a_r) / std::f64::consts::PI).sqrt())
    }

    /// The rod as a column: the field [`Cylinder::rod`], or a steel rod pinned at both ends
    /// with [`Cylinder::rod_diameter`]; `None` if neither is known (no rod check).
    #[must_use]
    pub fn rod(&self) -> Option<Rod> {
        self.rod.or_else(|| {
            Some(Rod {
                d: self.rod_diameter()?,
                e: buckling::STEEL_E,
                yield_strength: None,
                fixity: Fixity::PinnedPinned,
            })
        })
    }

    /// The initial pressures (P_p, P_r), Pa.
    #[must_use]
    pub fn initial_pressures(&self) -> (f64, f64) {
        match self.initial {
            InitialPressures::Given { p_p, p_r } => (p_p, p_r),
            InitialPressures::Hold { force, p_pre } => {
                hold_pressures(force, self.a_p, self.a_r, p_pre)
            }
        }
    }

    /// Check the parameters; errors name the model-file keys.
    pub fn validate(&self) -> Result<(), ParamError> {
        ParamError::positive("a_p", self.a_p)?;
        ParamError::positive("a_r", self.a_r)?;
        ParamError::finite("l0", self.l0)?;
        ParamError::non_negative("l_p0", self.l_p0)?;
        ParamError::positive("s_max", self.s_max)?;
        ParamError::finite("s0", self.s0)?;
        ParamError::positive("beta", self.beta)?;
        ParamError::finite("p_t", self.p_t)?;
        if !(self.l_r0.is_finite() && self.l_r0 >= self.s_max) {
            return Err(ParamError::Shape {
                param: "l_r0".into(),
                message: format!(
                    "the rod-side chamber length at s = 0 ({} m) must be at least the stroke s_max = {} m",
                    self.l_r0, self.s_max
                ),
            });
        }
        if self.end_stop.is_none() && !(0.0..=self.s_max).contains(&self.s0) {
            return Err(ParamError::Shape {
                param: "s0".into(),
                message: format!(
                    "initial stroke {} m is outside the stroke [0, {}] m",
                    self.s0, self.s_max
                ),
            });
        }
        if let Some(v) = self.v_min {
            ParamError::positive("v_min", v)?;
        }
        match self.initial {
            InitialPressures::Given { p_p, p_r } => {
                ParamError::finite("p_p0", p_p)?;
                ParamError::finite("p_r0", p_r)?;
            }
            InitialPressures::Hold { force, p_pre } => {
                ParamError::finite("hold_force", force)?;
                ParamError::finite("p_pre", p_pre)?;
            }
        }
        if let Some(r) = self.r_int {
            ParamError::positive("r_int", r)?;
        }
        if let Some(r) = self.r_ext {
            ParamError::positive("r_ext", r)?;
        }
        if let Some(rod) = self.rod() {
            rod.validate()?;
        }
        if let Some(e) = self.end_stop {
            ParamError::positive("k_stop", e.k)?;
            ParamError::non_negative("c_stop", e.c)?;
            ParamError::positive("stop_width", e.width)?;
        }
        Ok(())
    }

    /// The members, internal bonds and exposed ports (`mech`, `A`, `B`), for an instance
    /// called `instance` (signals inside refer to `<instance>_piston.s`).
    pub fn composite(self, instance: &str) -> Result<Composite, ParamError> {
        self.validate()?;
        let rod = self.rod();
        let stroke_signal = format!("{}.s", member_name(instance, "piston"));
        let stroke = || Param::modulated(vec![stroke_signal.clone()], |_, u| u[0]);
        let (p_p0, p_r0) = self.initial_pressures();
        let chamber = |side, area, l, p0| -> Result<Chamber, ParamError> {
            let c = Chamber::cylinder(side, area, l, self.beta, stroke(), p0)?
                .with_tank_pressure(self.p_t)?;
            let c = match self.v_min {
                Some(v) => c.with_v_min(v)?,
                None => c,
            };
            c.with_fluid(self.fluid)
        };
        let mut c = Composite::default();
        c.element("jp", ZeroJunction)
            .element("jr", ZeroJunction)
            .element(
                "chamber_p",
                chamber(Side::Piston, self.a_p, self.l_p0, p_p0)?,
            )
            .element("chamber_r", chamber(Side::Rod, self.a_r, self.l_r0, p_r0)?)
            .element(
                "piston",
                Piston::new(
                    self.a_p,
                    self.a_r,
                    self.l0,
                    self.s0,
                    self.s_max,
                    self.end_stop.is_none(),
                )?,
            )
            .element("rod", OneJunction);
        c.bond("b_cp", "jp", "chamber_p")
            .bond("b_cr", "jr", "chamber_r")
            .bond("b_pp", "jp", "piston.p")
            .bond("b_pr", "jr", "piston.r")
            .bond("b_rod", "piston.mech", "rod");
        if let Some(v) = self.valve {
            c.element(
                "valve",
                Valve::new(v.alpha, v.x_v, v.p_s, self.p_t, v.p_tr)?,
            );
            c.bond("b_va", "valve.A", "jp")
                .bond("b_vb", "valve.B", "jr");
        }
        if let Some(r) = self.r_int {
            c.element("leak", Leakage::internal(r)?);
            c.bond("b_la", "jp", "leak.a").bond("b_lb", "leak.b", "jr");
        }
        if let Some(r) = self.r_ext {
            c.element("leak_p", Leakage::to_tank(r, self.p_t)?)
                .element("leak_r", Leakage::to_tank(r, self.p_t)?);
            c.bond("b_lp", "jp", "leak_p").bond("b_lr", "jr", "leak_r");
        }
        let (length, b_rod, b_stop) = (
            format!("{}.l", member_name(instance, "piston")),
            format!("{}.e", member_name(instance, "b_rod")),
            format!("{}.e", member_name(instance, "b_stop")),
        );
        let mut forces = vec![(b_rod.as_str(), 1.0)];
        if let Some(e) = self.end_stop {
            c.element(
                "end_stop",
                EndStop::new(stroke(), 0.0, self.s_max, e.k, e.c, e.width)?,
            );
            c.bond("b_stop", "rod", "end_stop");
            forces.push((b_stop.as_str(), -1.0));
        }
        if let Some(rod) = rod {
            c.element("rod_check", RodCheck::new(rod, &length, &forces)?);
        }
        c.port("mech", "rod").port("A", "jp").port("B", "jr");
        Ok(c)
    }

    /// Add the cylinder's members to `g` as `<name>_<member>` with their internal bonds;
    /// returns the elements to bond the exposed ports to.
    pub fn add_to(self, g: &mut BondGraph, name: &str) -> Result<CylinderPorts, Error> {
        self.composite(name)?.add_to(name, g)?;
        let global = |l: &str| member_name(name, l);
        Ok(CylinderPorts {
            mech: global("rod"),
            a: global("jp"),
            b: global("jr"),
            piston: global("piston"),
        })
    }
}

/// Kind `hydraulics.cylinder`: the composite of this file (see the module documentation).
pub const KIND: KindDecl = KindDecl::composite(
    "hydraulics.cylinder",
    "valve-controlled cylinder: chambers, piston, leakage, valve, end stop; ports mech, A, B",
    &[
        ParamDecl::number("a_p", "m²", "piston area").positive(),
        ParamDecl::number("a_r", "m²", "annulus area").positive(),
        ParamDecl::number(
            "l_p0",
            "m",
            "piston-side chamber length at s = 0: V_p = A_p(l_p0 + s)",
        )
        .non_negative(),
        ParamDecl::number(
            "l_r0",
            "m",
            "rod-side chamber length at s = 0: V_r = A_r(l_r0 − s); l_r0 ≥ s_max",
        )
        .non_negative(),
        ParamDecl::number("s_max", "m", "usable stroke").positive(),
        ParamDecl::number("beta", "Pa", "bulk modulus").positive(),
        ParamDecl::number("l0", "m", "length at s = 0").default(0.0),
        ParamDecl::number(
            "s0",
            "m",
            "initial stroke (within [0, s_max] unless there is an end stop)",
        )
        .default(0.0),
        ParamDecl::number("v_min", "m³", "smallest chamber volume")
            .positive()
            .optional("1e-3 of each dead volume"),
        ParamDecl::number("p_t", "Pa", "tank pressure").default(0.0),
        ParamDecl::number(
            "hold_force",
            "N",
            "force the initial pressures hold (static initialisation)",
        )
        .default(0.0),
        ParamDecl::number(
            "p_pre",
            "Pa",
            "pressure of the less loaded chamber in the static initialisation",
        )
        .default(1e6),
        ParamDecl::number(
            "p_p0",
            "Pa",
            "initial piston-side pressure, instead of hold_force",
        )
        .optional("from hold_force"),
        ParamDecl::number(
            "p_r0",
            "Pa",
            "initial rod-side pressure, instead of hold_force",
        )
        .optional("from hold_force"),
        ParamDecl::modulated("x_v", "1", "spool stroke signal: includes the valve")
            .optional("no valve: drive ports A and B"),
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::number("p_s", "Pa", "supply pressure (with the valve)").optional("no valve"),
        orifice::P_TR,
        ParamDecl::number("r_int", "Pa·s/m³", "internal leakage resistance")
            .positive()
            .optional("no internal leakage"),
        ParamDecl::number(
            "r_ext",
            "Pa·s/m³",
            "external leakage resistance of each chamber to tank",
        )
        .positive()
        .optional("no external leakage"),
        ParamDecl::number("k_stop", "N/m", "end-stop stiffness at s = 0 and s = s_max")
            .positive()
            .optional("no end stop: leaving the stroke stops the run"),
        ParamDecl::number("c_stop", "N·s/m", "end-stop damping")
            .non_negative()
            .default(0.0),
        ParamDecl::number("stop_width", "m", "end-stop contact width")
            .positive()
            .default(1e-5),
        fluid::AIR_FRACTION,
        fluid::N_AIR,
        fluid::CAVITATION,
        fluid::P_VAPOUR,
        fluid::P_CAV_BAND,
        fluid::P_ATM,
        ParamDecl::number(
            "rod_d",
            "m",
            "rod diameter, for the buckling check (rod_check)",
        )
        .positive()
        .optional("from the areas: √(4(a_p − a_r)/π)"),
        ParamDecl::number("E", "Pa", "Young's modulus of the rod")
            .positive()
            .default(buckling::STEEL_E),
        ParamDecl::number(
            "yield",
            "Pa",
            "yield strength of the rod: the Johnson parabola for short rods",
        )
        .positive()
        .optional("Euler only"),
        ParamDecl::choice(
            "buckling",
            &Fixity::NAMES,
            "pinned-pinned",
            "end fixity of the rod as a column (K = 1, 2, 0.699, 0.5)",
        ),
    ],
    build,
)
.simplifications(&[
    Simplification::new(
        "no_internal_leakage",
        "piston seal tight: no r_int",
        &[Change::Unset("r_int")],
    )
    .members(&["leak"]),
    Simplification::new(
        "no_external_leakage",
        "rod and chamber seals tight: no r_ext",
        &[Change::Unset("r_ext")],
    )
    .members(&["leak_p", "leak_r"]),
    Simplification::new(
        "no_end_stop",
        "no end stop (leaving the stroke stops the run)",
        &[
            Change::Unset("k_stop"),
            Change::Unset("c_stop"),
            Change::Unset("stop_width"),
        ],
    )
    .members(&["end_stop"]),
])
.example(
    "a_p = 0.0045, a_r = 0.0025, l_p0 = 0.05, l_r0 = 0.55, s_max = 0.5, beta = 1.5e9, s0 = 0.1",
);

fn build(p: &dyn Params) -> Result<Composite, BuildError> {
    let mut c = Cylinder::new(
        p.number("a_p")?,
        p.number("a_r")?,
        p.number("l_p0")?,
        p.number("l_r0")?,
        p.number("s_max")?,
        p.number("beta")?,
    );
    c.l0 = p.number("l0")?;
    c.s0 = p.number("s0")?;
    c.v_min = p.optional("v_min")?;
    c.p_t = p.number("p_t")?;
    c.r_int = p.optional("r_int")?;
    c.r_ext = p.optional("r_ext")?;
    c.fluid = fluid::options(p)?;
    let fixity = buckling::fixity_of(&p.word("buckling")?)?;
    c.rod = match p.optional("rod_d")?.or_else(|| c.rod_diameter()) {
        Some(d) => Some(Rod {
            d,
            e: p.number("E")?,
            yield_strength: p.optional("yield")?,
            fixity,
        }),
        None => {
            if let Some(k) = ["E", "yield", "buckling"].into_iter().find(|k| p.has(k)) {
                return Err(BuildError::conflict(
                    k,
                    format!("`{k}` is a rod parameter, but a_p ≤ a_r gives no rod diameter"),
                )
                .hint("give the rod diameter `rod_d`"));
            }
            None
        }
    };
    c.initial = if p.has("p_p0") || p.has("p_r0") {
        if let Some(k) = ["hold_force", "p_pre"].into_iter().find(|k| p.has(k)) {
            return Err(BuildError::conflict(
                k,
                "give either `hold_force` (and `p_pre`) or `p_p0` and `p_r0`, not both",
            ));
        }
        InitialPressures::Given {
            p_p: p.number("p_p0")?,
            p_r: p.number("p_r0")?,
        }
    } else {
        InitialPressures::Hold {
            force: p.number("hold_force")?,
            p_pre: p.number("p_pre")?,
        }
    };
    if p.has("x_v") {
        c.valve = Some(ValveSpec {
            alpha: orifice::alpha_of(p)?,
            x_v: p.modulated("x_v")?,
            p_s: p.number("p_s")?,
            p_tr: p.number("p_tr")?,
        });
    } else if let Some(k) = ["alpha", "cd", "w", "rho", "p_s", "p_tr"]
        .into_iter()
        .find(|k| p.has(k))
    {
        // Valve parameters without a valve would be silently ignored: refuse them.
        return Err(BuildError::conflict(
            k,
            format!("`{k}` is a valve parameter, but there is no valve"),
        )
        .hint("give the spool stroke `x_v = \"<signal>\"` to include the valve"));
    }
    if p.has("k_stop") {
        c.end_stop = Some(EndStopSpec {
            k: p.number("k_stop")?,
            c: p.number("c_stop")?,
            width: p.number("stop_width")?,
        });
    } else if let Some(k) = ["c_stop", "stop_width"].into_iter().find(|k| p.has(k)) {
        return Err(BuildError::conflict(
            k,
            format!("`{k}` needs an end stop: give `k_stop` too"),
        ));
    }
    Ok(c.composite(p.name())?)
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact zeros and copied parameters are meant exactly
mod tests {
    use super::*;

    #[test]
    fn hold_pressures_follow_the_design_rule_and_give_the_force() {
        let (a_p, a_r) = (0.0452389, 0.0424115);
        for f in [207e3, -80.6e3, 0.0, 512e3] {
            let (pp, pr) = hold_pressures(f, a_p, a_r, 1e6);
            assert!((a_p * pp - a_r * pr - f).abs() <= 1e-9 * f.abs().max(1.0));
            if f >= 0.0 {
                assert_eq!(pr, 1e6);
            } else {
                assert_eq!(pp, 1e6);
            }
        }
        // the scene's sanity figure: 512 kN with the rod side at tank → P_p ≈ 11.3 MPa
        let (pp, _) = hold_pressures(512e3, a_p, a_r, 0.0);
        assert!((pp - 11.32e6).abs() < 0.01e6, "{pp}");
    }

    #[test]
    fn validate_names_the_model_keys() {
        let mut c = Cylinder::new(0.045, 0.042, 0.05, 2.75, 2.7, 1.5e9);
        assert!(c.validate().is_ok());
        c.l_r0 = 2.0;
        let e = c.validate().unwrap_err();
        assert!(
            matches!(e, ParamError::Shape { ref param, .. } if param == "l_r0"),
            "{e}"
        );
        c.l_r0 = 2.75;
        c.s0 = 3.0;
        assert!(c.validate().is_err());
        c.end_stop = Some(EndStopSpec {
            k: 1e9,
            c: 1e6,
            width: 1e-3,
        });
        assert!(
            c.validate().is_ok(),
            "with an end stop the drive may start past the end"
        );
    }

    #[test]
    fn composite_lists_its_members_and_ports() {
        let mut c = Cylinder::new(0.045, 0.042, 0.05, 2.75, 2.7, 1.5e9);
        c.r_int = Some(1e13);
        c.valve = Some(ValveSpec {
            alpha: 1e-5,
            x_v: Param::Const(0.0),
            p_s: 25e6,
            p_tr: 1e5,
        });
        let comp = c.composite("cyl1").unwrap();
        let names: Vec<&str> = comp.elements.iter().map(|(n, _)| n.as_str()).collect();
        for m in [
            "jp",
            "jr",
            "chamber_p",
            "chamber_r",
            "piston",
            "rod",
            "valve",
            "leak",
        ] {
            assert!(names.contains(&m), "{m} missing from {names:?}");
        }
        assert!(!names.contains(&"end_stop"));
        let ports: Vec<&str> = comp.ports.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(ports, ["mech", "A", "B"]);
    }

    #[test]
    fn the_rod_check_defaults_to_the_rod_the_areas_give() {
        let (a_p, a_r) = (0.045_238_9, 0.042_411_5);
        let c = Cylinder::new(a_p, a_r, 0.05, 2.75, 2.7, 1.5e9);
        let rod = c.rod().unwrap();
        assert!((rod.d - 0.06).abs() < 1e-6, "{}", rod.d);
        assert_eq!(rod.fixity, Fixity::PinnedPinned);
        assert!((rod.e - 210e9).abs() < 1.0);
        let comp = c.composite("cyl1").unwrap();
        let check = comp
            .elements
            .iter()
            .find(|(n, _)| n == "rod_check")
            .unwrap();
        let inputs: Vec<String> = check
            .1
            .signal_inputs()
            .into_iter()
            .map(|s| s.name)
            .collect();
        assert_eq!(inputs, ["cyl1_piston.l", "cyl1_b_rod.e"]);
        // with an end stop the rod force is F_c − F_stop
        let mut c = Cylinder::new(a_p, a_r, 0.05, 2.75, 2.7, 1.5e9);
        c.end_stop = Some(EndStopSpec {
            k: 1e9,
            c: 0.0,
            width: 1e-5,
        });
        let comp = c.composite("c").unwrap();
        let check = comp
            .elements
            .iter()
            .find(|(n, _)| n == "rod_check")
            .unwrap();
        assert_eq!(check.1.signal_inputs().len(), 3);
        // equal areas (a double-rod cylinder) give no diameter: no check unless rod_d is given
        let c = Cylinder::new(0.01, 0.01, 0.05, 2.75, 2.7, 1.5e9);
        assert!(c.rod().is_none());
        let comp = c.composite("c").unwrap();
        assert!(comp.elements.iter().all(|(n, _)| n != "rod_check"));
        // a bad rod is refused with its key
        let mut c = Cylinder::new(a_p, a_r, 0.05, 2.75, 2.7, 1.5e9);
        c.rod = Some(Rod {
            d: -0.06,
            e: 210e9,
            yield_strength: None,
            fixity: Fixity::FixedFree,
        });
        let e = c.validate().unwrap_err();
        assert!(e.to_string().contains("rod_d"), "{e}");
    }
}
