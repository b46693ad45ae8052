//! Model-file support: the composite kind `manipulator.planar_arm`, which builds an
//! [`ArmScene`] from one `[elements.<name>]` table.
//!
//! ```toml
//! [elements.crane]
//! kind = "manipulator.planar_arm"
//! gravity = "g"                       # m/s² along −y₀ (default 9.81)
//! q0 = [0, "-2*pi/3", "pi/6"]         # joint angles, then modal coordinates (missing: 0)
//! u0 = []                             # speeds (missing: 0)
//! damping = [0, 0, "r_p", "r_e", "r_e", "r_e", "r_e", "r_e", "r_e"]   # diag D (missing: 0)
//! quadrature_points = 16              # Gauss–Legendre points per link (reference; non-sine modes)
//! links = [
//!   { type = "beam", length = "L1", E = "E", rho = "rho", A = "A", I = "I", modes = 3 },
//!   { type = "beam", length = "L2", E = "E", rho = "rho", A = "A", I = "I", modes = 3 },
//!   { type = "pendulum", length = "L3", mass = "m3" },
//! ]
//! actuators = [                       # pins: { ground = [x, y] } or { link = 1, x = … }
//!   { from = { ground = ["d0*cos(beta3)", "-d0*sin(beta3)"] }, to = { link = 1, x = "h1" } },
//!   { from = { link = 1, x = "L1 - h2" }, to = { link = 2, x = "h3" } },
//! ]
//! lumped_masses = [{ link = 1, x = "h1", mass = "m_p" }, …]
//! lumped_model = "springs"            # "springs" (default), "rigid" or "none"
//! lumped_stiffness = "k_c"            # N/m, with "springs"
//! lumped_damping = "c_c"              # N·s/m, with "springs"
//! paper_reactions = false             # also publish rho{k}_paper (springs only)
//! ```
//!
//! Links are numbered from 1 as in the paper. A link table has `type` = `"beam"` (length, E,
//! rho, A, I, modes), `"rigid"` (length, mass_per_length, rotary_inertia_per_length) or
//! `"pendulum"` (length, mass), and may list `point_masses = [{ x, mass, inertia }]`. All
//! numbers may be expressions of the model's parameters; events that change a parameter the
//! arm uses (damping) rebuild its members.

use std::cell::RefCell;

use bg_model::expr::Expr;
use bg_model::{Composite, ElementSpec, ErrorKind, ModelError, Registry};
use toml::Value;

use crate::actuator::LinearActuator;
use crate::link::{Link, PointMass};
use crate::lumped_mass::LumpedMass;
use crate::pin::Pin;
use crate::scene::{ArmScene, LumpedMassModel};

/// Register the manipulator's kinds: `manipulator.planar_arm`.
pub fn register(registry: &mut Registry) {
    registry.register_composite(
        "manipulator.planar_arm",
        "planar serial arm of rigid/flexible links (assumed modes), actuators and lumped masses, with reaction forces; ports cyl1.., u",
        build_planar_arm,
    );
}

fn build_planar_arm(s: &ElementSpec<'_>) -> Result<Composite, ModelError> {
    let scene = scene(s)?;
    scene
        .composite(&|l| s.member(l))
        .map_err(|e| s.param_error(&e))
}

/// A nested TOML table read key by key, with unknown keys reported.
struct Table<'a, 's> {
    spec: &'a ElementSpec<'s>,
    key: &'a str,
    path: String,
    table: &'a toml::Table,
    asked: RefCell<Vec<String>>,
}

impl<'a, 's> Table<'a, 's> {
    fn new(
        spec: &'a ElementSpec<'s>,
        key: &'a str,
        path: String,
        v: &'a Value,
    ) -> Result<Self, ModelError> {
        match v {
            Value::Table(table) => Ok(Self {
                spec,
                key,
                path,
                table,
                asked: RefCell::new(Vec::new()),
            }),
            other => Err(bad(
                spec,
                key,
                format!("`{path}` must be a table {{ … }}, not {}", other.type_str()),
            )),
        }
    }
    fn get(&self, k: &str) -> Option<&'a Value> {
        self.asked.borrow_mut().push(k.to_owned());
        self.table.get(k)
    }
    fn num(&self, k: &str) -> Result<f64, ModelError> {
        let v = self
            .get(k)
            .ok_or_else(|| bad(self.spec, self.key, format!("`{}` needs `{k}`", self.path)))?;
        number(self.spec, self.key, &format!("{}.{k}", self.path), v)
    }
    fn num_or(&self, k: &str, default: f64) -> Result<f64, ModelError> {
        self.get(k).map_or(Ok(default), |v| {
            number(self.spec, self.key, &format!("{}.{k}", self.path), v)
        })
    }
    fn str_or(&self, k: &str, default: &'a str) -> Result<&'a str, ModelError> {
        match self.get(k) {
            None => Ok(default),
            Some(Value::String(s)) => Ok(s),
            Some(_) => Err(bad(
                self.spec,
                self.key,
                format!("`{}.{k}` must be a string", self.path),
            )),
        }
    }
    /// A 1-based link number as a 0-based index.
    fn link(&self, k: &str) -> Result<usize, ModelError> {
        let v = self.num(k)?;
        if v.fract() != 0.0 || v < 1.0 {
            return Err(bad(
                self.spec,
                self.key,
                format!("`{}.{k}` = {v} must be a link number 1, 2, …", self.path),
            ));
        }
        Ok(v as usize - 1)
    }
    fn finish(self) -> Result<(), ModelError> {
        let asked = self.asked.borrow();
        match self.table.keys().find(|k| !asked.contains(k)) {
            None => Ok(()),
            Some(k) => {
                let mut e = bad(
                    self.spec,
                    self.key,
                    format!("`{}` has an unknown key `{k}`", self.path),
                );
                e.hint = Some(format!("`{}` takes: {}", self.path, asked.join(", ")));
                Err(e)
            }
        }
    }
}

fn bad(s: &ElementSpec<'_>, key: &str, message: String) -> ModelError {
    s.error(
        key,
        ErrorKind::BadParameter,
        format!("({}) {message}", s.kind),
    )
}

/// A constant number: a TOML number or an expression of the model's parameters.
fn number(s: &ElementSpec<'_>, key: &str, path: &str, v: &Value) -> Result<f64, ModelError> {
    let x = match v {
        Value::Float(f) => *f,
        Value::Integer(i) => *i as f64,
        Value::String(text) => {
            let e = Expr::parse(text)
                .map_err(|e| bad(s, key, format!("cannot read `{path}` = \"{text}\": {e}")))?;
            let (c, inputs) = s.compile(key, &e)?;
            if let Some(n) = inputs.first() {
                return Err(bad(
                    s,
                    key,
                    format!("`{path}` must be constant, but reads `{n}`"),
                ));
            }
            c.eval(&[])
        }
        other => {
            return Err(bad(
                s,
                key,
                format!("`{path}` must be a number, not {}", other.type_str()),
            ))
        }
    };
    if x.is_finite() {
        Ok(x)
    } else {
        Err(bad(
            s,
            key,
            format!("`{path}` evaluates to {x}, which is not finite"),
        ))
    }
}

/// The array at `key`, or an empty one.
fn array<'a>(s: &'a ElementSpec<'_>, key: &str) -> Result<&'a [Value], ModelError> {
    match s.raw(key) {
        None => Ok(&[]),
        Some(Value::Array(a)) => Ok(a),
        Some(other) => Err(bad(
            s,
            key,
            format!("`{key}` must be an array [ … ], not {}", other.type_str()),
        )),
    }
}

fn link(s: &ElementSpec<'_>, k: usize, v: &Value) -> Result<Link, ModelError> {
    let t = Table::new(s, "links", format!("links[{}]", k + 1), v)?;
    let fail = |e: crate::ManipulatorError| bad(s, "links", format!("links[{}]: {e}", k + 1));
    let length = t.num("length")?;
    let mut l = match t.str_or("type", "beam")? {
        "beam" => {
            let beam = Link::beam(length, t.num("E")?, t.num("rho")?, t.num("A")?, t.num("I")?)
                .map_err(fail)?;
            let modes = t.num_or("modes", 0.0)?;
            if modes.fract() != 0.0 || !(0.0..=64.0).contains(&modes) {
                return Err(bad(
                    s,
                    "links",
                    format!("links[{}].modes = {modes} must be an integer 0..=64", k + 1),
                ));
            }
            beam.with_sine_modes(modes as u32).map_err(fail)?
        }
        "rigid" => {
            let (m, j) = (
                t.num_or("mass_per_length", 0.0)?,
                t.num_or("rotary_inertia_per_length", 0.0)?,
            );
            Link::rigid(length, m)
                .and_then(|l| l.with_rotary_inertia(j))
                .map_err(fail)?
        }
        "pendulum" => Link::pendulum(length, t.num("mass")?).map_err(fail)?,
        other => {
            return Err(bad(
                s,
                "links",
                format!(
                    "links[{}].type = \"{other}\": use \"beam\", \"rigid\" or \"pendulum\"",
                    k + 1
                ),
            ));
        }
    };
    if let Some(pm) = t.get("point_masses") {
        let Value::Array(items) = pm else {
            return Err(bad(
                s,
                "links",
                format!("links[{}].point_masses must be an array", k + 1),
            ));
        };
        for (m, item) in items.iter().enumerate() {
            let p = Table::new(
                s,
                "links",
                format!("links[{}].point_masses[{}]", k + 1, m + 1),
                item,
            )?;
            let mass = PointMass {
                x: p.num("x")?,
                mass: p.num("mass")?,
                inertia: p.num_or("inertia", 0.0)?,
            };
            p.finish()?;
            l = l.with_point_mass(mass).map_err(fail)?;
        }
    }
    t.finish()?;
    Ok(l)
}

fn pin(t: &Table<'_, '_>) -> Result<Pin, ModelError> {
    if let Some(g) = t.get("ground") {
        let xy = match g {
            Value::Array(a) if a.len() == 2 => a,
            _ => {
                return Err(bad(
                    t.spec,
                    t.key,
                    format!("`{}.ground` must be [x, y]", t.path),
                ))
            }
        };
        let x = number(t.spec, t.key, &format!("{}.ground[1]", t.path), &xy[0])?;
        let y = number(t.spec, t.key, &format!("{}.ground[2]", t.path), &xy[1])?;
        return Ok(Pin::ground(x, y));
    }
    Ok(Pin::on_link(t.link("link")?, t.num("x")?))
}

fn scene(s: &ElementSpec<'_>) -> Result<ArmScene, ModelError> {
    let links = array(s, "links")?
        .iter()
        .enumerate()
        .map(|(k, v)| link(s, k, v))
        .collect::<Result<Vec<_>, _>>()?;
    if links.is_empty() {
        return Err(bad(
            s,
            "links",
            "needs `links = [ … ]` with at least one link".into(),
        ));
    }
    let mut scene = ArmScene::new(links, s.number_or("gravity", 9.81)?);
    let points = s.number_or("quadrature_points", scene.quadrature_points as f64)?;
    if points.fract() != 0.0 || !(1.0..=512.0).contains(&points) {
        return Err(bad(
            s,
            "quadrature_points",
            format!("`quadrature_points` = {points} must be an integer 1..=512"),
        ));
    }
    scene.quadrature_points = points as usize;
    scene.q0 = s.vector_or("q0", Vec::new())?;
    scene.u0 = s.vector_or("u0", Vec::new())?;
    scene.damping = s.vector_or("damping", Vec::new())?;
    // Damping by kind, independent of the number of modes: one value per joint and one for
    // every modal coordinate (or one per link).
    if s.has("joint_damping") || s.has("modal_damping") {
        if !scene.damping.is_empty() {
            return Err(bad(s, "damping", "give either `damping` (one entry per coordinate) or `joint_damping` and `modal_damping`, not both".into()));
        }
        let n_links = scene.links.len();
        let joints = s.vector_or("joint_damping", vec![0.0; n_links])?;
        if joints.len() != n_links {
            return Err(bad(
                s,
                "joint_damping",
                format!(
                    "`joint_damping` needs one value per joint ({n_links}), got {}",
                    joints.len()
                ),
            ));
        }
        let modal = s.vector_or("modal_damping", vec![0.0])?;
        if modal.len() != 1 && modal.len() != n_links {
            return Err(bad(
                s,
                "modal_damping",
                format!(
                    "`modal_damping` needs one value, or one per link ({n_links}), got {}",
                    modal.len()
                ),
            ));
        }
        let mut d = joints;
        for (i, l) in scene.links.iter().enumerate() {
            let r = if modal.len() == 1 { modal[0] } else { modal[i] };
            d.extend(std::iter::repeat_n(r, l.modes().len()));
        }
        scene.damping = d;
    }
    for (k, v) in array(s, "actuators")?.iter().enumerate() {
        let t = Table::new(s, "actuators", format!("actuators[{}]", k + 1), v)?;
        let ends = ["from", "to"].map(|e| {
            let v = t.get(e).ok_or_else(|| {
                bad(
                    s,
                    "actuators",
                    format!("`actuators[{}]` needs `{e}`", k + 1),
                )
            })?;
            let p = Table::new(s, "actuators", format!("actuators[{}].{e}", k + 1), v)?;
            let pin = pin(&p)?;
            p.finish()?;
            Ok::<_, ModelError>(pin)
        });
        let [a, b] = ends;
        scene.actuators.push(LinearActuator::new(a?, b?));
        t.finish()?;
    }
    for (k, v) in array(s, "lumped_masses")?.iter().enumerate() {
        let t = Table::new(s, "lumped_masses", format!("lumped_masses[{}]", k + 1), v)?;
        scene.lumped_masses.push(LumpedMass {
            pin: Pin::on_link(t.link("link")?, t.num("x")?),
            mass: t.num("mass")?,
        });
        t.finish()?;
    }
    scene.paper_reactions = match s.raw("paper_reactions") {
        None => false,
        Some(Value::Boolean(b)) => *b,
        Some(_) => {
            return Err(bad(
                s,
                "paper_reactions",
                "`paper_reactions` must be true or false".into(),
            ))
        }
    };
    // The spring parameters are read whatever the model, so that `--set` can switch
    // `lumped_model` alone.
    let stiffness = s.number_or("lumped_stiffness", f64::NAN)?;
    let damping = s.number_or("lumped_damping", 0.0)?;
    scene.lumped_model = match s.string_or("lumped_model", "springs")?.as_str() {
        "springs" => {
            if scene.lumped_masses.is_empty() {
                LumpedMassModel::Omitted
            } else if stiffness.is_nan() {
                return Err(bad(
                    s,
                    "lumped_model",
                    "lumped masses on springs need `lumped_stiffness` (N/m)".into(),
                ));
            } else {
                LumpedMassModel::Springs { stiffness, damping }
            }
        }
        "rigid" => LumpedMassModel::Rigid,
        "none" => LumpedMassModel::Omitted,
        other => {
            return Err(bad(
                s,
                "lumped_model",
                format!("`lumped_model` = \"{other}\": use \"springs\", \"rigid\" or \"none\""),
            ));
        }
    };
    Ok(scene)
}
