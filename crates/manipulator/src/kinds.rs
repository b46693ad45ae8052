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
//! geometric_stiffening = false        # keep the axial shortening of the bent links
//! base = { y = "0.5*sin(0.7*t)", roll = "0.02*sin(0.5*t)" }   # a moving base (default: fixed)
//! payload = { type = "wire", mass = "m3", EA = 5e7, length = 6, winch = true,
//!             landing = { height = "-20 + 0.8*sin(0.6*t)", k = 1e8, lambda = 2e6 } }
//! ```
//!
//! Links are numbered from 1 as in the paper. A link table has `type` = `"beam"` (length, E,
//! rho, A, I, modes), `"rigid"` (length, mass_per_length, rotary_inertia_per_length) or
//! `"pendulum"` (length, mass), and may list `point_masses = [{ x, mass, inertia }]`. All
//! numbers may be expressions of the model's parameters; events that change a parameter the
//! arm uses (damping) rebuild its members. Every key is declared in [`PLANAR_ARM`]'s tables.

use bondgraph::kind::{BuildError, Change, KindDecl, ParamDecl, Params, Range, Simplification};
use bondgraph::{Composite, Param, ParamError};

use crate::actuator::LinearActuator;
use crate::link::{Link, PointMass, Profile};
use crate::lumped_mass::LumpedMass;
use crate::pin::Pin;
use crate::quadrature::GaussLegendre;
use crate::scene::{ArmScene, LumpedMassModel};

/// Every kind of this crate.
pub const KINDS: &[KindDecl] = &[PLANAR_ARM];

const POINT_MASS: &[ParamDecl] = &[
    ParamDecl::number("x", "m", "position along the link"),
    ParamDecl::number("mass", "kg", "mass").non_negative(),
    ParamDecl::number("inertia", "kg·m²", "rotary inertia about its centre")
        .non_negative()
        .default(0.0),
];

const LINK: &[ParamDecl] = &[
    ParamDecl::choice(
        "type",
        &["beam", "rigid", "pendulum"],
        "beam",
        "flexible beam, rigid link, or massless rod with a tip mass",
    ),
    ParamDecl::number("length", "m", "link length").positive(),
    ParamDecl::number("E", "Pa", "Young's modulus (beam)")
        .positive()
        .optional("beam only"),
    ParamDecl::number("rho", "kg/m³", "density (beam)")
        .positive()
        .optional("beam only"),
    ParamDecl::number("A", "m²", "cross-section area (beam)")
        .positive()
        .optional("beam only"),
    ParamDecl::number("I", "m⁴", "second moment of area (beam)")
        .positive()
        .optional("beam only"),
    ParamDecl::count("modes", "assumed modes (beam)")
        .range(Range::closed(0.0, 64.0))
        .default(0.0),
    ParamDecl::number("mass_per_length", "kg/m", "mass per length (rigid)")
        .non_negative()
        .default(0.0),
    ParamDecl::number(
        "rotary_inertia_per_length",
        "kg·m",
        "rotary inertia per length (rigid)",
    )
    .non_negative()
    .default(0.0),
    ParamDecl::number("mass", "kg", "tip mass (pendulum)")
        .non_negative()
        .optional("pendulum only"),
    ParamDecl::tables("point_masses", POINT_MASS, "point masses on the link").optional("none"),
    ParamDecl::vector(
        "EI_samples",
        "N·m²",
        "EI(x) sampled at equally spaced x from 0 to L, linear between (beam; replaces E·I)",
    )
    .optional("uniform"),
    ParamDecl::vector(
        "rhoA_samples",
        "kg/m",
        "ρA(x) sampled likewise (beam; replaces rho·A)",
    )
    .optional("uniform"),
    ParamDecl::vector(
        "rhoI_samples",
        "kg·m",
        "ρI(x) sampled likewise (beam; replaces rho·I)",
    )
    .optional("uniform"),
    ParamDecl::modulated(
        "EI_of_x",
        "N·m²",
        "EI as an expression of x, the distance from the joint (m), or a table called at x, \
         \"boom_EI(x)\"; sampled at 4097 equally spaced x when built (beam; replaces E·I)",
    )
    .of("x")
    .optional("uniform"),
    ParamDecl::modulated(
        "rhoA_of_x",
        "kg/m",
        "ρA as an expression of x likewise (beam; replaces rho·A)",
    )
    .of("x")
    .optional("uniform"),
    ParamDecl::modulated(
        "rhoI_of_x",
        "kg·m",
        "ρI as an expression of x likewise (beam; replaces rho·I)",
    )
    .of("x")
    .optional("uniform"),
    ParamDecl::table(
        "section",
        SECTION,
        "cross-section for stresses: A with I, c_top, c_bottom or W_top, W_bottom (docs/stress.md)",
    )
    .optional("none"),
];

/// A link's cross-section for stress recovery (docs/stress.md): each entry a number or an
/// expression of x like the `*_of_x` profiles.
const SECTION: &[ParamDecl] = &[
    ParamDecl::modulated("A", "m²", "area (for N/A)").of("x"),
    ParamDecl::modulated("I", "m⁴", "second moment of area (with c_top, c_bottom)")
        .of("x")
        .optional("give W_top and W_bottom"),
    ParamDecl::modulated(
        "c_top",
        "m",
        "distance of the +y fibre from the neutral axis",
    )
    .of("x")
    .optional("give W_top"),
    ParamDecl::modulated(
        "c_bottom",
        "m",
        "distance of the −y fibre from the neutral axis",
    )
    .of("x")
    .optional("give W_bottom"),
    ParamDecl::modulated("W_top", "m³", "section modulus of the +y fibre, I/c_top")
        .of("x")
        .optional("give I and c_top"),
    ParamDecl::modulated(
        "W_bottom",
        "m³",
        "section modulus of the −y fibre, I/c_bottom",
    )
    .of("x")
    .optional("give I and c_bottom"),
];

const STRESS_AT: &[ParamDecl] = &[
    ParamDecl::count("link", "the link, 1, 2, …").range(Range::at_least(1.0)),
    ParamDecl::number("x", "m", "distance from its joint along the chord"),
];

/// Samples of a profile given as an expression of x (equally spaced from 0 to L).
const PROFILE_SAMPLES: usize = 4097;

const PIN: &[ParamDecl] = &[
    ParamDecl::vector("ground", "m", "a pin on the ground at [x, y]").optional("a pin on a link"),
    ParamDecl::count("link", "the link the pin is on, 1, 2, …")
        .range(Range::at_least(1.0))
        .optional("on the ground"),
    ParamDecl::number("x", "m", "position along that link").optional("on the ground"),
];

const ACTUATOR: &[ParamDecl] = &[
    ParamDecl::table("from", PIN, "the pin the actuator pushes from"),
    ParamDecl::table("to", PIN, "the pin it pushes"),
];

const LUMPED_MASS: &[ParamDecl] = &[
    ParamDecl::count("link", "the link it sits on, 1, 2, …").range(Range::at_least(1.0)),
    ParamDecl::number("x", "m", "position along that link"),
    ParamDecl::number("mass", "kg", "mass").positive(),
];

const BASE: &[ParamDecl] = &[
    ParamDecl::modulated(
        "x",
        "m",
        "horizontal position of joint 1, an expression of t",
    )
    .default(0.0),
    ParamDecl::modulated(
        "y",
        "m",
        "vertical position of joint 1 (up), an expression of t",
    )
    .default(0.0),
    ParamDecl::modulated(
        "roll",
        "rad",
        "roll of the base frame (counter-clockwise), an expression of t",
    )
    .default(0.0),
];

const LANDING: &[ParamDecl] = &[
    ParamDecl::modulated("height", "m", "height of the landing surface (inertial, up), an expression of t").default(0.0),
    ParamDecl::number("k", "", "contact stiffness k of F = k δⁿ + λ δⁿ δ̇ (N/mⁿ)").positive(),
    ParamDecl::number("n", "", "contact exponent n (1.5: Hertz)").positive().default(1.5),
    ParamDecl::number("lambda", "", "Hunt–Crossley damping λ (N·s/mⁿ⁺¹); λ = 3k(1 − e)/(2 v) for a restitution e at impact speed v").non_negative().default(0.0),
    ParamDecl::number("mu", "", "Coulomb friction coefficient").non_negative().default(0.0),
    ParamDecl::number("slip_speed", "m/s", "sliding speed over which friction builds up (tanh)").positive().default(0.01),
];

const PAYLOAD: &[ParamDecl] = &[
    ParamDecl::choice(
        "type",
        &["wire"],
        "wire",
        "a point mass on an elastic wire from the end of the last link",
    ),
    ParamDecl::number("mass", "kg", "payload mass").positive(),
    ParamDecl::number("EA", "N", "axial stiffness of the wire; k = EA/L").positive(),
    ParamDecl::number(
        "damping",
        "s",
        "Kelvin–Voigt time constant of the wire: c = damping·EA/L",
    )
    .non_negative()
    .default(0.0),
    ParamDecl::number(
        "length",
        "m",
        "paid-out length (at the start, with a winch)",
    )
    .positive(),
    ParamDecl::flag(
        "winch",
        false,
        "a winch pays the wire out through the exposed port `wire` (tension, pay-out speed)",
    ),
    ParamDecl::number(
        "slack_band",
        "m",
        "stretch over which the tension's slack/taut transition is smoothed (C¹)",
    )
    .positive()
    .default(1e-6),
    ParamDecl::flag(
        "start_stretched",
        true,
        "start hanging at rest with the static stretch m g L/EA",
    ),
    ParamDecl::table(
        "landing",
        LANDING,
        "a landing surface under the payload (Hunt–Crossley contact)",
    )
    .optional("none"),
];

/// Kind `manipulator.planar_arm`.
pub const PLANAR_ARM: KindDecl = KindDecl::composite(
    "manipulator.planar_arm",
    "planar serial arm of rigid/flexible links (assumed modes), actuators and lumped masses, with reaction forces; ports cyl1.., u",
    &[
        ParamDecl::tables("links", LINK, "the links from the base, numbered 1, 2, …"),
        ParamDecl::number("gravity", "m/s²", "gravity along −y₀").default(9.81),
        ParamDecl::count("quadrature_points", "Gauss–Legendre points per link (reference; non-sine modes)")
            .range(Range::closed(1.0, 512.0))
            .default(GaussLegendre::DEFAULT_POINTS as f64),
        ParamDecl::vector("q0", "", "initial joint angles (rad), then modal coordinates; missing: 0").optional("0"),
        ParamDecl::vector("u0", "", "initial speeds; missing: 0").optional("0"),
        ParamDecl::vector("damping", "", "diagonal of D, one per coordinate; missing: 0").optional("0"),
        ParamDecl::vector("joint_damping", "N·m·s", "damping of each joint, instead of `damping`").optional("0"),
        ParamDecl::vector("modal_damping", "", "damping of every modal coordinate (one value, or one per link)").optional("0"),
        ParamDecl::tables("actuators", ACTUATOR, "linear actuators between two pins").optional("none"),
        ParamDecl::tables("lumped_masses", LUMPED_MASS, "lumped masses on the links (cylinder bodies)").optional("none"),
        ParamDecl::choice("lumped_model", &["springs", "rigid", "none"], "springs", "how lumped masses attach"),
        ParamDecl::number("lumped_stiffness", "N/m", "spring stiffness of lumped masses (with \"springs\")").positive().optional("needed with springs"),
        ParamDecl::number("lumped_damping", "N·s/m", "spring damping of lumped masses (with \"springs\")").non_negative().default(0.0),
        ParamDecl::flag("paper_reactions", false, "also publish rho{k}_paper (springs only)"),
        ParamDecl::flag("geometric_stiffening", false, "keep the axial shortening of bent links (axial-force stiffening; docs/manipulator.md)"),
        ParamDecl::tables("stress_at", STRESS_AT, "sections whose N, V, M, M_modal, sigma_top, sigma_bottom are published (docs/stress.md)").optional("none"),
        ParamDecl::count("stress_grid", "equally spaced sections per link published as grid{k}.* (bg-sim stress sets it)")
            .range(Range::closed(0.0, 4096.0))
            .default(0.0),
        ParamDecl::table("payload", PAYLOAD, "a payload on an elastic wire of varying length from the end of the last link (docs/offshore.md)").optional("none"),
        ParamDecl::table("base", BASE, "a moving base (a vessel): the ground frame's position and roll as functions of time (docs/offshore.md)").optional("fixed"),
    ],
    build_planar_arm,
)
.simplifications(&[
    Simplification::new("rigid_lumped_masses", "lumped masses moving rigidly with their pins (no pin springs)", &[Change::Set("lumped_model", "\"rigid\"")])
        .members(&["spring", "damper"]),
    Simplification::new("no_lumped_masses", "lumped masses left out", &[Change::Set("lumped_model", "\"none\"")])
        .members(&["spring", "damper", "masses", "gravity"]),
    Simplification::new("rigid_links", "every beam rigid (0 modes)", &[Change::Set("links[*].modes", "0")])
        .members(&["c", "r"]),
])
.example("links = [{ type = \"beam\", length = 1.0, E = 2e11, rho = 7800, A = 1e-3, I = 1e-6, modes = 1 }], q0 = [0.1]");

fn build_planar_arm(p: &dyn Params) -> Result<Composite, BuildError> {
    Ok(scene(p)?.composite(p.name())?)
}

fn within(prefix: String) -> impl Fn(ParamError) -> BuildError {
    move |e| BuildError::from(e).within(&prefix)
}

fn link(k: usize, t: &dyn Params) -> Result<Link, BuildError> {
    let fail = || within(format!("links[{}]", k + 1));
    let length = t.number("length")?;
    let kind = t.word("type")?;
    let only = |keys: &[&str], what: &str| -> Result<(), BuildError> {
        match keys.iter().find(|key| t.has(key)) {
            Some(key) => Err(BuildError::conflict(
                key,
                format!("`{key}` does not apply to a {what} link"),
            )
            .within(&format!("links[{}]", k + 1))),
            None => Ok(()),
        }
    };
    let mut l = match kind.as_str() {
        "rigid" => {
            only(
                &[
                    "E",
                    "rho",
                    "A",
                    "I",
                    "modes",
                    "mass",
                    "EI_samples",
                    "rhoA_samples",
                    "rhoI_samples",
                    "EI_of_x",
                    "rhoA_of_x",
                    "rhoI_of_x",
                ],
                "rigid",
            )?;
            let (m, j) = (
                t.number("mass_per_length")?,
                t.number("rotary_inertia_per_length")?,
            );
            Link::rigid(length, m)
                .and_then(|l| l.with_rotary_inertia(j))
                .map_err(fail())?
        }
        "pendulum" => {
            only(
                &[
                    "E",
                    "rho",
                    "A",
                    "I",
                    "modes",
                    "mass_per_length",
                    "rotary_inertia_per_length",
                    "EI_samples",
                    "rhoA_samples",
                    "rhoI_samples",
                    "EI_of_x",
                    "rhoA_of_x",
                    "rhoI_of_x",
                ],
                "pendulum",
            )?;
            Link::pendulum(length, t.number("mass")?).map_err(fail())?
        }
        _ => {
            only(
                &["mass", "mass_per_length", "rotary_inertia_per_length"],
                "beam",
            )?;
            let beam = Link::beam(
                length,
                t.number("E")?,
                t.number("rho")?,
                t.number("A")?,
                t.number("I")?,
            )
            .map_err(fail())?;
            let samples = |key: &str, of_x: &str| -> Result<Option<Vec<f64>>, BuildError> {
                match (t.has(key), t.has(of_x)) {
                    (true, true) => Err(BuildError::conflict(
                        of_x,
                        format!("links[{}]: give `{key}` or `{of_x}`, not both", k + 1),
                    )
                    .within(&format!("links[{}]", k + 1))),
                    (true, false) => Ok(Some(t.vector(key)?)),
                    (false, true) => {
                        let at = format!("links[{}]", k + 1);
                        profile_of_x(&t.modulated(of_x)?, of_x, &at, length)
                            .map(Some)
                            .map_err(|e| e.within(&at))
                    }
                    (false, false) => Ok(None),
                }
            };
            let profile = Profile {
                bending_stiffness: samples("EI_samples", "EI_of_x")?,
                mass_per_length: samples("rhoA_samples", "rhoA_of_x")?,
                rotary_inertia_per_length: samples("rhoI_samples", "rhoI_of_x")?,
            };
            let beam = if profile == Profile::default() {
                beam
            } else {
                beam.with_profile(profile).map_err(fail())?
            };
            beam.with_sine_modes(t.count("modes")? as u32)
                .map_err(fail())?
        }
    };
    for m in t.tables("point_masses")? {
        let mass = PointMass {
            x: m.number("x")?,
            mass: m.number("mass")?,
            inertia: m.number("inertia")?,
        };
        l = l.with_point_mass(mass).map_err(fail())?;
    }
    Ok(l)
}

/// A profile given as an expression of x (or a table called at x), sampled at
/// [`PROFILE_SAMPLES`] equally spaced points from 0 to `length` (linear between: exact for a
/// linear profile; for a curved one off by at most `(L/4096)² max|f''|/8`).
fn profile_of_x(p: &Param, key: &str, at: &str, length: f64) -> Result<Vec<f64>, BuildError> {
    let x_at = |k: usize| length * k as f64 / (PROFILE_SAMPLES - 1) as f64;
    match p {
        Param::Const(c) => Ok(vec![*c; 2]),
        Param::Modulated { inputs, law, .. } => {
            if let Some(other) = inputs.iter().find(|n| n.as_str() != "x") {
                return Err(BuildError::invalid(
                    key,
                    format!(
                        "`{at}.{key}` may read only x (the distance from the joint, m), not `{other}`"
                    ),
                )
                .hint(
                    "a table is called at x, e.g. \"boom_EI(x)\"; parameters of [parameters] \
                     may appear",
                ));
            }
            let mut at = vec![0.0; inputs.len()];
            Ok((0..PROFILE_SAMPLES)
                .map(|k| {
                    at.fill(x_at(k));
                    law(0.0, &at)
                })
                .collect())
        }
    }
}

/// The `section = { … }` of a link table, if any.
fn section(
    t: &dyn Params,
    length: f64,
    at: &str,
) -> Result<Option<crate::stress::CrossSection>, BuildError> {
    let Some(s) = t.table("section")? else {
        return Ok(None);
    };
    let get = |key: &str| -> Result<Option<Vec<f64>>, BuildError> {
        if !s.has(key) {
            return Ok(None);
        }
        let v = profile_of_x(&s.modulated(key)?, key, at, length).map_err(|e| e.within(at))?;
        Ok(Some(v))
    };
    let area = get("A")?
        .ok_or_else(|| BuildError::missing("A", format!("`{at}` needs its area `A`")).within(at))?;
    let built = match (
        get("I")?,
        get("c_top")?,
        get("c_bottom")?,
        get("W_top")?,
        get("W_bottom")?,
    ) {
        (Some(i), Some(ct), Some(cb), None, None) => {
            crate::stress::CrossSection::from_distances(length, area, &i, &ct, &cb)
        }
        (None, None, None, Some(wt), Some(wb)) => {
            crate::stress::CrossSection::from_moduli(length, area, wt, wb)
        }
        _ => {
            return Err(BuildError::invalid(
                "section",
                format!(
                    "`{at}` needs `A` with either `I`, `c_top`, `c_bottom` or `W_top`, `W_bottom`"
                ),
            )
            .within(at)
            .hint("section = { A = \"A\", I = \"I\", c_top = 0.19, c_bottom = 0.19 }"))
        }
    };
    built.map(Some).map_err(|e| BuildError::from(e).within(at))
}

fn pin(t: &dyn Params, at: &str) -> Result<Pin, BuildError> {
    if t.has("ground") {
        if let Some(k) = ["link", "x"].into_iter().find(|k| t.has(k)) {
            return Err(BuildError::conflict(
                k,
                "a pin is either on the ground (`ground = [x, y]`) or on a link (`link`, `x`)",
            )
            .within(at));
        }
        let xy = t.vector("ground")?;
        let [x, y] = xy[..] else {
            return Err(BuildError::invalid("ground", "`ground` must be [x, y]").within(at));
        };
        return Ok(Pin::ground(x, y));
    }
    if !t.has("link") {
        return Err(BuildError::missing(
            "link",
            "a pin needs `ground = [x, y]`, or `link` and `x`",
        )
        .within(at));
    }
    Ok(Pin::on_link(t.count("link")? - 1, t.number("x")?))
}

fn scene(p: &dyn Params) -> Result<ArmScene, BuildError> {
    let links = p
        .tables("links")?
        .iter()
        .enumerate()
        .map(|(k, t)| link(k, t.as_ref()))
        .collect::<Result<Vec<_>, _>>()?;
    let stiffening = p.flag("geometric_stiffening")?;
    let links: Vec<Link> = links
        .into_iter()
        .map(|l| l.with_geometric_stiffening(stiffening))
        .collect();
    if links.is_empty() {
        return Err(BuildError::missing(
            "links",
            "needs `links = [ … ]` with at least one link",
        ));
    }
    let sections = p
        .tables("links")?
        .iter()
        .zip(&links)
        .enumerate()
        .map(|(k, (t, l))| section(t.as_ref(), l.length(), &format!("links[{}].section", k + 1)))
        .collect::<Result<Vec<_>, _>>()?;
    let mut scene = ArmScene::new(links, p.number("gravity")?);
    scene.sections = sections;
    for t in p.tables("stress_at")? {
        scene.stress_at.push((t.count("link")? - 1, t.number("x")?));
    }
    scene.stress_grid = p.count("stress_grid")?;
    scene.quadrature_points = p.count("quadrature_points")?;
    scene.q0 = p.vector("q0")?;
    scene.u0 = p.vector("u0")?;
    scene.damping = p.vector("damping")?;
    // Damping by kind, independent of the number of modes: one value per joint and one for
    // every modal coordinate (or one per link).
    if p.has("joint_damping") || p.has("modal_damping") {
        if !scene.damping.is_empty() {
            return Err(BuildError::conflict("damping", "give either `damping` (one entry per coordinate) or `joint_damping` and `modal_damping`, not both"));
        }
        let n_links = scene.links.len();
        let joints = if p.has("joint_damping") {
            p.vector("joint_damping")?
        } else {
            vec![0.0; n_links]
        };
        if joints.len() != n_links {
            return Err(BuildError::invalid(
                "joint_damping",
                format!(
                    "`joint_damping` needs one value per joint ({n_links}), got {}",
                    joints.len()
                ),
            ));
        }
        let modal = if p.has("modal_damping") {
            p.vector("modal_damping")?
        } else {
            vec![0.0]
        };
        if modal.len() != 1 && modal.len() != n_links {
            return Err(BuildError::invalid(
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
    for (k, t) in p.tables("actuators")?.iter().enumerate() {
        let at = |e: &str| format!("actuators[{}].{e}", k + 1);
        let (Some(from), Some(to)) = (t.table("from")?, t.table("to")?) else {
            return Err(BuildError::missing(
                "actuators",
                format!("`actuators[{}]` needs `from` and `to`", k + 1),
            ));
        };
        scene.actuators.push(LinearActuator::new(
            pin(from.as_ref(), &at("from"))?,
            pin(to.as_ref(), &at("to"))?,
        ));
    }
    for t in p.tables("lumped_masses")? {
        scene.lumped_masses.push(LumpedMass {
            pin: Pin::on_link(t.count("link")? - 1, t.number("x")?),
            mass: t.number("mass")?,
        });
    }
    scene.paper_reactions = p.flag("paper_reactions")?;
    if let Some(t) = p.table("payload")? {
        let at = |e: BuildError| e.within("payload");
        let landing = match t.table("landing").map_err(at)? {
            None => None,
            Some(l) => {
                let at = |e: BuildError| e.within("payload.landing");
                Some(crate::elements::Landing {
                    height: l.motion("height").map_err(at)?,
                    stiffness: l.number("k").map_err(at)?,
                    exponent: l.number("n").map_err(at)?,
                    damping: l.number("lambda").map_err(at)?,
                    friction: l.number("mu").map_err(at)?,
                    slip_speed: l.number("slip_speed").map_err(at)?,
                })
            }
        };
        scene.payload = Some(crate::elements::WireSpec {
            mass: t.number("mass").map_err(at)?,
            ea: t.number("EA").map_err(at)?,
            damping: t.number("damping").map_err(at)?,
            length: t.number("length").map_err(at)?,
            winch: t.flag("winch").map_err(at)?,
            slack_band: t.number("slack_band").map_err(at)?,
            start_stretched: t.flag("start_stretched").map_err(at)?,
            landing,
        });
    }
    if let Some(b) = p.table("base")? {
        scene.base = Some(crate::base::Base {
            x: b.motion("x").map_err(|e| e.within("base"))?,
            y: b.motion("y").map_err(|e| e.within("base"))?,
            roll: b.motion("roll").map_err(|e| e.within("base"))?,
        });
    }
    // The spring parameters are read whatever the model, so that `--set` can switch
    // `lumped_model` alone.
    let stiffness = p.optional("lumped_stiffness")?;
    let damping = p.number("lumped_damping")?;
    scene.lumped_model = match p.word("lumped_model")?.as_str() {
        "rigid" => LumpedMassModel::Rigid,
        "none" => LumpedMassModel::Omitted,
        _ if scene.lumped_masses.is_empty() => LumpedMassModel::Omitted,
        _ => match stiffness {
            Some(stiffness) => LumpedMassModel::Springs { stiffness, damping },
            None => {
                return Err(BuildError::missing(
                    "lumped_stiffness",
                    "lumped masses on springs need `lumped_stiffness` (N/m)",
                )
                .hint("give `lumped_stiffness`, or `lumped_model = \"rigid\"` or \"none\""))
            }
        },
    };
    Ok(scene)
}
