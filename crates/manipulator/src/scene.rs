//! [`ArmScene`]: one configuration — links, modes, joints, pins, masses, gravity, damping —
//! turned into the bond graph of Fig. 5 (the manipulator part).
//!
//! ```text
//!            arm (I-field: p, q) ──┐
//!   c (C-field: −G + Kq) ──────────┤
//!   r (R-field: D) ────────────────┤ 1  j   (common flow u)
//!   act{c}.1 ──────────────────────┤        act{c}.2 ← exposed port `cyl{c}` (F_c, l̇_c)
//!   lump.1 ────────────────────────┘        lump.2 ← pins (1) ← link (0) ← masses_j (1) ← gravity
//!                                                               link → rel (1) → spring, damper
//!                                                                     masses_j → masses (I)
//!   rho: reaction forces (signals)
//! ```
//!
//! The scene chooses the modes per link (0 = rigid) through its links, and how the lumped
//! cylinder masses move ([`LumpedMassModel`]): on x/y spring–dampers (the paper), rigidly
//! attached to their pins (point masses of the links), or left out. The members are named
//! `<instance>_<local>` with the locals above; `<instance>_arm.q`, `<instance>_act1.l1`,
//! `<instance>_rho.rho5`, … are their signals. Exposed ports: `cyl1`, `cyl2`, … (one per
//! actuator: effort F_c, positive pushing its pins apart; flow l̇_c) and `u` (the arm's
//! 1-junction, for further generalized forces).

use std::sync::Arc;

use bondgraph::kind::member_name;
use bondgraph::{
    BondGraph, Capacitor, Composite, ElementId, Error, OneJunction, ParamError, Resistor,
    ZeroJunction,
};
use nalgebra::DVector;

use crate::actuator::LinearActuator;
use crate::arm::PlanarArm;
use crate::base::Base;
use crate::elements::ReactionInputs;
use crate::elements::{
    ActuatorTransformer, ArmCompliance, ArmDamping, ArmInertia, ArmReactions, LumpedGravity,
    LumpedMassTransformer,
};
use crate::elements::{BaseLoads, BaseMotion, BASE_OUTPUTS, OUT_ALPHA, OUT_FIELD, OUT_OMEGA};
use crate::elements::{WirePayload, WireSpec, PAYLOAD_OUTPUTS};
use crate::link::{Link, PointMass};
use crate::lumped_mass::LumpedMass;
use crate::quadrature::GaussLegendre;

/// How the lumped cylinder masses move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LumpedMassModel {
    /// Each mass has its own momentum and is tied to its pin by an x/y spring (stiffness,
    /// N/m) and damper (N·s/m), starting at its pin with the springs unloaded (section 4.2).
    Springs {
        /// Spring stiffness k_c (N/m), > 0.
        stiffness: f64,
        /// Damping c_c (N·s/m), ≥ 0.
        damping: f64,
    },
    /// Each mass moves rigidly with its pin: a point mass of the link.
    Rigid,
    /// The masses are left out.
    Omitted,
}

/// A planar arm scene.
#[derive(Clone, Debug)]
pub struct ArmScene {
    /// The links, in order from the base.
    pub links: Vec<Link>,
    /// Gravity (m/s², along −y₀).
    pub gravity: f64,
    /// Gauss–Legendre points per link.
    pub quadrature_points: usize,
    /// Initial coordinates: the joint angles, optionally followed by the modal coordinates
    /// (missing ones are 0).
    pub q0: Vec<f64>,
    /// Initial speeds (missing ones are 0).
    pub u0: Vec<f64>,
    /// Diagonal damping per coordinate (missing ones are 0).
    pub damping: Vec<f64>,
    /// Linear actuators (cylinders), each exposed as a port `cyl{c}`.
    pub actuators: Vec<LinearActuator>,
    /// The lumped cylinder masses.
    pub lumped_masses: Vec<LumpedMass>,
    /// How they move.
    pub lumped_model: LumpedMassModel,
    /// With lumped masses on springs, also publish the reaction forces of the paper's
    /// variant (masses moving rigidly with their pins) as `rho{k}_paper`.
    pub paper_reactions: bool,
    /// Cross-sections for stress recovery, one per link (`None`: none declared).
    pub sections: Vec<Option<crate::stress::CrossSection>>,
    /// Sections (link 0-based, x) whose N, V, M, σ are published by the stress block.
    pub stress_at: Vec<(usize, f64)>,
    /// Equally spaced sections per link published as vectors `grid{k}.*` (0: none).
    pub stress_grid: usize,
    /// The moving base ([`base`](crate::base)), if any: adds the members `base` (its motion
    /// as signals), `inertial` (the loads of its acceleration) and the pedestal's reaction.
    pub base: Option<Base>,
    /// A payload on an elastic wire from the end of the last chord
    /// ([`WirePayload`](crate::elements::WirePayload)): the member `payload`, with the
    /// exposed port `wire` when a winch pays it out.
    pub payload: Option<WireSpec>,
}

/// Pad `v` with zeros to length `n`, or complain that it is longer.
fn padded(name: &str, v: &[f64], n: usize) -> Result<Vec<f64>, ParamError> {
    if v.len() > n {
        return Err(ParamError::shape(
            name,
            format!("has {} values, the arm has {n} coordinates", v.len()),
        ));
    }
    let mut out = v.to_vec();
    out.resize(n, 0.0);
    Ok(out)
}

impl ArmScene {
    /// A scene with `links` under `gravity`, at rest with all coordinates zero, no damping,
    /// no actuators and no lumped masses.
    #[must_use]
    pub fn new(links: Vec<Link>, gravity: f64) -> Self {
        Self {
            links,
            gravity,
            quadrature_points: GaussLegendre::DEFAULT_POINTS,
            q0: Vec::new(),
            u0: Vec::new(),
            damping: Vec::new(),
            actuators: Vec::new(),
            lumped_masses: Vec::new(),
            lumped_model: LumpedMassModel::Omitted,
            paper_reactions: false,
            sections: Vec::new(),
            stress_at: Vec::new(),
            stress_grid: 0,
            base: None,
            payload: None,
        }
    }

    /// The arm this scene simulates (with the lumped masses as point masses if they are
    /// rigidly attached).
    pub fn arm(&self) -> Result<PlanarArm, ParamError> {
        let mut links = self.links.clone();
        if self.lumped_model == LumpedMassModel::Rigid {
            for m in &self.lumped_masses {
                let crate::Pin::Link { link, x } = m.pin else {
                    return Err(ParamError::shape(
                        "lumped_masses",
                        "a lumped mass must sit on a link",
                    ));
                };
                let l = links.get_mut(link).ok_or_else(|| {
                    ParamError::shape("lumped_masses", format!("link {} does not exist", link + 1))
                })?;
                *l = l.clone().with_point_mass(PointMass {
                    x,
                    mass: m.mass,
                    inertia: 0.0,
                })?;
            }
        }
        PlanarArm::with_quadrature(links, self.gravity, self.quadrature_points)
    }

    /// The members, internal bonds and exposed ports; `member` gives the global name of a
    /// member from its local name (for the signals members read from each other).
    pub fn composite(&self, instance: &str) -> Result<Composite, ParamError> {
        let member = |l: &str| member_name(instance, l);
        // shared by the elements of one model, which runs on one thread: the arm keeps the
        // frames at the last configuration in a RefCell (PlanarArm::pose_in), so it is not Sync
        #[allow(clippy::arc_with_non_send_sync)]
        let arm = Arc::new(self.arm()?);
        let n = arm.n();
        let q0 = padded("q0", &self.q0, n)?;
        let u0 = padded("u0", &self.u0, n)?;
        let damping = padded("damping", &self.damping, n)?;
        let springs = match self.lumped_model {
            LumpedMassModel::Springs { .. } => self.lumped_masses.clone(),
            _ => Vec::new(),
        };
        for m in &springs {
            arm.check_lumped_mass(m)?;
        }
        let q = format!("{}.q", member("arm"));
        let mut c = Composite::default();
        let mut inertia = ArmInertia::new(arm.clone(), q0.clone(), u0.clone())?;
        let base_signal = |k: usize| format!("{}.{}", member("base"), BASE_OUTPUTS[k]);
        if let Some(base) = &self.base {
            if arm.has_geometric_stiffening() {
                return Err(ParamError::shape(
                    "base",
                    "a moving base is not combined with geometric_stiffening yet",
                ));
            }
            if !springs.is_empty() {
                return Err(ParamError::shape(
                    "base",
                    "a moving base needs the lumped masses rigid or left out (lumped_model = \"rigid\" or \"none\"): the loads of the base's roll on masses hanging on springs are not modelled",
                ));
            }
            if base.rolls() {
                let omega0 = base.roll.eval(0.0)[1];
                inertia =
                    inertia.on_rolling_base(base_signal(OUT_OMEGA), base_signal(OUT_ALPHA), omega0);
            }
            c.element("base", BaseMotion::new(base.clone(), self.gravity))
                .element(
                    "inertial",
                    BaseLoads::new(
                        arm.clone(),
                        &q,
                        [base_signal(OUT_FIELD), base_signal(OUT_FIELD + 1)],
                    ),
                )
                .bond("b_inertial", "j", "inertial");
        }
        c.element("arm", inertia)
            .element("j", OneJunction)
            .element("c", ArmCompliance::new(arm.clone(), &q))
            .element("r", ArmDamping::new(damping)?);
        c.bond("b_arm", "j", "arm")
            .bond("b_c", "j", "c")
            .bond("b_r", "j", "r")
            .port("u", "j");
        let mut forces = Vec::new();
        for (k, act) in self.actuators.iter().enumerate() {
            let (name, cyl) = (format!("act{}", k + 1), format!("cyl{}", k + 1));
            let mtf =
                ActuatorTransformer::new(arm.clone(), vec![*act], &q, &q0)?.numbered_from(k + 1);
            c.element(&name, mtf)
                .bond(&format!("b_{name}"), &format!("{name}.1"), "j")
                .port(&cyl, &format!("{name}.2"));
            forces.push(format!("{}.2.e", member(&name)));
        }
        let mut pin_forces = None;
        if let (LumpedMassModel::Springs { stiffness, damping }, false) =
            (self.lumped_model, springs.is_empty())
        {
            ParamError::positive("lumped_stiffness", stiffness)?;
            let pins: Vec<_> = springs.iter().map(|m| m.pin).collect();
            let masses: Vec<f64> = springs.iter().map(|m| m.mass).collect();
            let v0 =
                arm.lumped_mass_jacobian(&arm.pose(&q0), &pins) * DVector::from_column_slice(&u0);
            c.element("lump", LumpedMassTransformer::new(arm.clone(), pins, &q)?)
                .element("pins", OneJunction)
                .element("link", ZeroJunction)
                .element("rel", OneJunction)
                .element(
                    "spring",
                    Capacitor::multi(1.0 / stiffness, vec![0.0; 2 * masses.len()])?,
                )
                .element("damper", Resistor::new(damping)?)
                .element("masses_j", OneJunction)
                .element(
                    "masses",
                    crate::elements::lumped_masses(&masses, v0.as_slice())?,
                )
                .element("gravity", LumpedGravity::new(masses, self.gravity)?);
            c.bond("b_lump", "lump.1", "j")
                .bond("b_pins", "pins", "lump.2")
                .bond("b_link_pins", "link", "pins")
                .bond("b_masses_link", "masses_j", "link")
                .bond("b_rel", "link", "rel")
                .bond("b_spring", "rel", "spring")
                .bond("b_damper", "rel", "damper")
                .bond("b_gravity", "gravity", "masses_j")
                .bond("b_masses", "masses_j", "masses");
            pin_forces = Some(format!("{}.2.e", member("lump")));
        }
        let mut tip_load = None;
        if let Some(spec) = &self.payload {
            let base = self.base.clone().unwrap_or_else(Base::still);
            c.element(
                "payload",
                WirePayload::new(arm.clone(), spec.clone(), base, self.gravity, &q, &q0)?,
            )
            .bond("b_payload", "j", "payload.1");
            if spec.winch {
                c.port("wire", "payload.wire");
            }
            let out = |k: usize| format!("{}.{}", member("payload"), PAYLOAD_OUTPUTS[k]);
            tip_load = Some([out(7), out(8)]);
        }
        let arm_name = member("arm");
        let inputs = ReactionInputs {
            q: q.clone(),
            u: format!("{arm_name}.u"),
            udot: format!("{arm_name}.udot"),
            forces,
            pin_forces,
            base: self.base.as_ref().map(|_| {
                [
                    base_signal(OUT_OMEGA),
                    base_signal(OUT_ALPHA),
                    base_signal(OUT_FIELD),
                    base_signal(OUT_FIELD + 1),
                ]
            }),
            tip_load,
        };
        if !self.stress_at.is_empty() || self.stress_grid > 0 {
            // only when asked for: the block is read by outputs alone (docs/stress.md)
            if self.base.is_some() || self.payload.is_some() {
                // the free body of docs/stress.md sums the loads of a fixed base and a rigid
                // pendulum payload; the inertial field of a moving base and the wire's
                // tension are not among them yet
                return Err(ParamError::shape(
                    "stress_at",
                    "stress recovery is not combined with a moving `base` or a wire `payload` yet: \
                     remove the stress outputs (or `stress_at`), or run the scene on a fixed base \
                     with the rigid payload",
                ));
            }
            let joints = padded("damping", &self.damping, n)?[..arm.n_links()].to_vec();
            c.element(
                "stress",
                crate::stress::ArmStress::new(
                    arm.clone(),
                    &self.actuators,
                    &springs,
                    joints,
                    &self.sections,
                    &self.stress_at,
                    self.stress_grid,
                    inputs.clone(),
                )?,
            );
        }
        c.element(
            "rho",
            ArmReactions::new(arm, &self.actuators, &springs, inputs)?
                .with_paper_variant(self.paper_reactions),
        );
        Ok(c)
    }

    /// Add the scene to `g` as `<name>_<local>` members (what the model loader does with
    /// the composite); returns the exposed ports as (name, element, port index).
    pub fn add_to(
        &self,
        g: &mut BondGraph,
        name: &str,
    ) -> Result<Vec<(String, ElementId, Option<usize>)>, Error> {
        let ports = self.composite(name)?.add_to(name, g)?;
        ports
            .into_iter()
            .map(|(p, inner)| {
                let (el, port) = inner
                    .split_once('.')
                    .map_or((inner.as_str(), None), |(e, p)| (e, Some(p)));
                let id = g
                    .find(el)
                    .ok_or_else(|| bondgraph::GraphError::UnknownElement {
                        name: el.to_owned(),
                    })?;
                let port = port.map(|q| g.port_index(id, q)).transpose()?;
                Ok((p, id, port))
            })
            .collect()
    }
}
