//! Model-file builders: how each `hydraulics.*` kind reads its parameters (see
//! `docs/hydraulics.md` for the table). Errors point at the offending key.

use bg_model::{Composite, ElementSpec, ErrorKind, ModelError, Registry};
use bondgraph::{Element, ParamError};

use crate::cylinder::{EndStopSpec, InitialPressures, ValveSpec};
use crate::{orifice, Chamber, Cylinder, EndStop, Leakage, Orifice, Piston, Side, Valve};

type Built = Result<Box<dyn Element>, ModelError>;

/// Register every `hydraulics.*` kind.
pub fn register(r: &mut Registry) {
    r.register(
        "hydraulics.chamber",
        "oil volume, C with pressure state: dP/dt = β/V(s)·Q, V = A(l⁰ ± s) or fixed; publishes V",
        chamber,
    );
    r.register(
        "hydraulics.piston",
        "cylinder piston, TF pair: F = A_p·P_p − A_r·P_r, Q_p = A_p·ṡ, Q_r = −A_r·ṡ; state s, publishes l",
        piston,
    );
    r.register(
        "hydraulics.end_stop",
        "stiff spring–damper past either end of the stroke",
        end_stop,
    );
    r.register(
        "hydraulics.leakage",
        "internal leakage between ports a and b: Q = (P_a − P_b)/r",
        |s| {
            Leakage::internal(s.number("r", "leakage resistance, Pa·s/m³")?)
                .map(|e| Box::new(e) as _)
                .map_err(|e| s.param_error(&e))
        },
    );
    r.register(
        "hydraulics.tank_leakage",
        "external leakage to tank: Q = (P − p_tank)/r",
        |s| {
            Leakage::to_tank(
                s.number("r", "leakage resistance, Pa·s/m³")?,
                s.number_or("p_tank", 0.0)?,
            )
            .map(|e| Box::new(e) as _)
            .map_err(|e| s.param_error(&e))
        },
    );
    r.register(
        "hydraulics.orifice",
        "orifice a → b: Q = α·x·regRoot(P_a − P_b)",
        orifice_kind,
    );
    r.register(
        "hydraulics.valve",
        "4/3 directional valve, eqs. 29–30 with regRoot: ports A (piston side), B (rod side)",
        valve,
    );
    r.register_composite(
        "hydraulics.cylinder",
        "valve-controlled cylinder: chambers, piston, leakage, valve, end stop; ports mech, A, B",
        cylinder,
    );
}

pub(crate) fn boxed<E: Element + 'static>(s: &ElementSpec<'_>, e: Result<E, ParamError>) -> Built {
    e.map(|e| Box::new(e) as _).map_err(|e| s.param_error(&e))
}

fn optional(s: &ElementSpec<'_>, key: &str) -> Result<Option<f64>, ModelError> {
    if s.has(key) {
        s.number(key, "").map(Some)
    } else {
        Ok(None)
    }
}

pub(crate) fn boolean(s: &ElementSpec<'_>, key: &str, default: bool) -> Result<bool, ModelError> {
    match s.raw(key) {
        None => Ok(default),
        Some(toml::Value::Boolean(b)) => Ok(*b),
        Some(_) => Err(s.error(
            key,
            ErrorKind::BadParameter,
            format!("({}) `{key}` must be true or false", s.kind),
        )),
    }
}

/// α from `alpha`, or from `cd`, `w` and `rho` (eq. 31).
pub(crate) fn alpha(s: &ElementSpec<'_>) -> Result<f64, ModelError> {
    if s.has("alpha") {
        for k in ["cd", "w", "rho"] {
            if s.has(k) {
                return Err(s.error(
                    k,
                    ErrorKind::BadParameter,
                    format!(
                        "({}) give either `alpha` or `cd`, `w`, `rho`, not both",
                        s.kind
                    ),
                ));
            }
        }
        return s.number("alpha", "orifice coefficient α, m³/(s·√Pa)");
    }
    if !(s.has("cd") || s.has("w") || s.has("rho")) {
        let mut e = s.error(
            "alpha",
            ErrorKind::MissingParameter,
            format!(
                "({}) needs the orifice coefficient: `alpha`, or `cd`, `w` and `rho`",
                s.kind
            ),
        );
        e.hint = Some(format!(
            "add e.g. `cd = 0.6, w = 0.0007, rho = 880.0` to `{}` (α = cd·w·√(2/rho))",
            s.name
        ));
        return Err(e);
    }
    let cd = s.number("cd", "discharge coefficient")?;
    let w = s.number("w", "orifice area at full opening, m²")?;
    let rho = s.number("rho", "oil density, kg/m³")?;
    orifice::alpha(cd, w, rho).map_err(|e| s.param_error(&e))
}

fn chamber(s: &ElementSpec<'_>) -> Built {
    let beta = s.number("beta", "bulk modulus, Pa")?;
    let p0 = s.number_or("p0", 0.0)?;
    let c = if s.has("volume") {
        Chamber::fixed(s.number("volume", "volume, m³")?, beta, p0)
    } else {
        let side = match s.string_or("side", "piston")?.as_str() {
            "piston" => Side::Piston,
            "rod" => Side::Rod,
            other => {
                return Err(s.error(
                    "side",
                    ErrorKind::BadParameter,
                    format!(
                    "(hydraulics.chamber) `side` must be \"piston\" or \"rod\", not \"{other}\""
                ),
                ))
            }
        };
        Chamber::cylinder(
            side,
            s.number("area", "piston or annulus area, m²")?,
            s.number("dead_length", "chamber length at s = 0, m")?,
            beta,
            s.param("stroke", "stroke signal, m (e.g. \"cyl.s\")")?,
            p0,
        )
    };
    let mut c = c.map_err(|e| s.param_error(&e))?;
    if let Some(v) = optional(s, "v_min")? {
        c = c.with_v_min(v).map_err(|e| s.param_error(&e))?;
    }
    let (p_tank, p_nominal) = (s.number_or("p_tank", 0.0)?, s.number_or("p_nominal", 1e6)?);
    let c = c
        .with_tank_pressure(p_tank)
        .and_then(|c| c.with_nominal_pressure(p_nominal))
        .map_err(|e| s.param_error(&e))?;
    Ok(Box::new(c))
}

fn piston(s: &ElementSpec<'_>) -> Built {
    let p = Piston::new(
        s.number("a_p", "piston area, m²")?,
        s.number("a_r", "annulus area, m²")?,
        s.number_or("l0", 0.0)?,
        s.number_or("s0", 0.0)?,
        s.number("s_max", "usable stroke, m")?,
        boolean(s, "guard", true)?,
    );
    boxed(s, p)
}

fn end_stop(s: &ElementSpec<'_>) -> Built {
    let e = EndStop::new(
        s.param("stroke", "stroke signal, m")?,
        s.number_or("s_min", 0.0)?,
        s.number("s_max", "upper end of the stroke, m")?,
        s.number("k", "stiffness, N/m")?,
        s.number("c", "damping, N·s/m")?,
        s.number_or("width", 1e-5)?,
    );
    boxed(s, e)
}

fn orifice_kind(s: &ElementSpec<'_>) -> Built {
    let o = Orifice::new(
        alpha(s)?,
        s.param_or("opening", 1.0)?,
        s.number_or("p_tr", 1e5)?,
    );
    boxed(s, o)
}

fn valve(s: &ElementSpec<'_>) -> Built {
    let v = Valve::new(
        alpha(s)?,
        s.param("x_v", "spool stroke signal, e.g. \"spool.out\"")?,
        s.number("p_s", "supply pressure, Pa")?,
        s.number_or("p_t", 0.0)?,
        s.number_or("p_tr", 1e5)?,
    );
    boxed(s, v)
}

fn cylinder(s: &ElementSpec<'_>) -> Result<Composite, ModelError> {
    let mut c = Cylinder::new(
        s.number("a_p", "piston area, m²")?,
        s.number("a_r", "annulus area, m²")?,
        s.number("l_p0", "piston-side chamber length at s = 0, m")?,
        s.number("l_r0", "rod-side chamber length at s = 0, m")?,
        s.number("s_max", "usable stroke, m")?,
        s.number("beta", "bulk modulus, Pa")?,
    );
    c.l0 = s.number_or("l0", 0.0)?;
    c.s0 = s.number_or("s0", 0.0)?;
    c.v_min = optional(s, "v_min")?;
    c.p_t = s.number_or("p_t", 0.0)?;
    c.r_int = optional(s, "r_int")?;
    c.r_ext = optional(s, "r_ext")?;
    let given = s.has("p_p0") || s.has("p_r0");
    c.initial = if given {
        if let Some(k) = ["hold_force", "p_pre"].into_iter().find(|k| s.has(k)) {
            return Err(s.error(
                k,
                ErrorKind::BadParameter,
                "(hydraulics.cylinder) give either `hold_force` (and `p_pre`) or `p_p0` and `p_r0`, not both",
            ));
        }
        InitialPressures::Given {
            p_p: s.number("p_p0", "initial piston-side pressure, Pa")?,
            p_r: s.number("p_r0", "initial rod-side pressure, Pa")?,
        }
    } else {
        InitialPressures::Hold {
            force: s.number_or("hold_force", 0.0)?,
            p_pre: s.number_or("p_pre", 1e6)?,
        }
    };
    if s.has("x_v") {
        c.valve = Some(ValveSpec {
            alpha: alpha(s)?,
            x_v: s.param("x_v", "spool stroke signal")?,
            p_s: s.number("p_s", "supply pressure, Pa")?,
            p_tr: s.number_or("p_tr", 1e5)?,
        });
    }
    if s.has("k_stop") {
        c.end_stop = Some(EndStopSpec {
            k: s.number("k_stop", "end-stop stiffness, N/m")?,
            c: s.number_or("c_stop", 0.0)?,
            width: s.number_or("stop_width", 1e-5)?,
        });
    }
    // Valve parameters without a valve would be silently ignored: refuse them.
    if c.valve.is_none() {
        for k in ["alpha", "cd", "w", "rho", "p_s", "p_tr"] {
            if s.has(k) {
                return Err(s.error(
                    k,
                    ErrorKind::BadParameter,
                    format!("(hydraulics.cylinder) `{k}` is a valve parameter, but there is no valve"),
                )
                .hint_text("give the spool stroke `x_v = \"<signal>\"` to include the valve"));
            }
        }
    }
    for k in ["c_stop", "stop_width"] {
        if c.end_stop.is_none() && s.has(k) {
            return Err(s.error(
                k,
                ErrorKind::BadParameter,
                format!("(hydraulics.cylinder) `{k}` needs an end stop: give `k_stop` too"),
            ));
        }
    }
    c.composite(s.name).map_err(|e| s.param_error(&e))
}

/// Set a hint on an error (the loader's own setter is crate-private).
trait HintText {
    fn hint_text(self, hint: &str) -> Self;
}

impl HintText for ModelError {
    fn hint_text(mut self, hint: &str) -> Self {
        self.hint = Some(hint.to_owned());
        self
    }
}
