//! The reaction forces in the passive joints as a signal block (section 5, eqs. 84–98).
//!
//! Reads the I-field's configuration `<arm>.q`, speeds `<arm>.u` and accelerations
//! `<arm>.udot`, and, when present, the cylinder forces (the efforts on the actuator MTFs'
//! port 2, in actuator order) and the spring–damper forces on the lumped masses' pins (the
//! effort on the lumped-mass MTF's port 2). Publishes `rho1 … rho{2 n_links}`: ρ_{2j−1},
//! ρ_{2j} is the force that the inboard body exerts on link j through joint j, in the axes
//! of frame j (see [`ArmKinematics::reactions`]). With lumped masses on springs it can also
//! publish `rho{k}_paper` ([`with_paper_variant`](ArmReactions::with_paper_variant)): the
//! same with the masses moving rigidly with their pins, as the paper's eqs. 91–94 have it.
//!
//! [`ArmKinematics::reactions`]: crate::ArmKinematics::reactions

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{CausalRule, Element, Io, ParamError, Ports, SignalSpec};
use nalgebra::Vector2;

use crate::actuator::LinearActuator;
use crate::arm::{Frames, PlanarArm, Station};
use crate::kinematics::ArmKinematics;
use crate::lumped_mass::LumpedMass;
use crate::pin::PinPoint;

/// Signals the block reads.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ReactionInputs {
    /// The configuration (`arm.q`).
    pub q: String,
    /// The speeds (`arm.u`).
    pub u: String,
    /// The accelerations (`arm.udot`).
    pub udot: String,
    /// Per actuator, its force (`act1.2.e`); empty without actuators.
    pub forces: Vec<String>,
    /// The pin forces of the lumped masses on springs (`lump.2.e`), if any.
    pub pin_forces: Option<String>,
    /// On a moving base ([`base`](crate::base)): the signals θ̇, θ̈ and the apparent
    /// gravity's x, y in the base's axes. The block then also publishes the pedestal's
    /// reaction `F_ped_x`, `F_ped_y` (N, base axes) and `M_ped` (N·m, about joint 1,
    /// counter-clockwise): the load of the arm on the vessel.
    pub base: Option<[String; 4]>,
    /// A force on the end of the last chord (base axes, a 2-signal pair: the wire's pull,
    /// `payload.Fx`, `payload.Fy`), if any.
    pub tip_load: Option<[String; 2]>,
}

impl ReactionInputs {
    /// The signals read, in the order a block's `io.input(k)` sees them: q, u, u̇ (n each),
    /// one force per actuator, the springs' pin forces (2 per spring), then the base's four
    /// and the tip load's two where given.
    pub fn signal_specs(&self, n: usize, n_springs: usize) -> Vec<SignalSpec> {
        let v = |name: &str, dim| SignalSpec {
            name: name.to_owned(),
            dim,
        };
        let mut s = vec![v(&self.q, n), v(&self.u, n), v(&self.udot, n)];
        s.extend(self.forces.iter().map(|f| v(f, 1)));
        if let Some(p) = &self.pin_forces {
            s.push(v(p, 2 * n_springs));
        }
        s.extend(self.base.iter().flatten().map(|b| v(b, 1)));
        s.extend(self.tip_load.iter().flatten().map(|b| v(b, 1)));
        s
    }
}

/// The reaction-force block of a [`PlanarArm`].
#[derive(Debug)]
pub struct ArmReactions {
    arm: Arc<PlanarArm>,
    inputs: ReactionInputs,
    /// Per actuator, its pins (a, b) resolved on the arm.
    acts: Vec<(PinPoint, PinPoint)>,
    springs: Vec<(Station, f64)>,
    /// The end of the last chord (where a tip load acts).
    tip: Station,
    paper: bool,
    ws: RefCell<Workspace>,
}

/// Buffers for one evaluation.
#[derive(Debug)]
struct Workspace {
    frames: Frames,
    /// q, u, u̇ (n each).
    q: Vec<f64>,
    u: Vec<f64>,
    udot: Vec<f64>,
    /// The force of each actuator on its pin b (frame 0).
    act_forces: Vec<Vector2<f64>>,
    /// ρ, then the paper's variant.
    rho: Vec<f64>,
    rho_paper: Vec<f64>,
    /// With a moving base: the reactions without loads, M, E, Ṁu and the field forces.
    all: Vec<f64>,
    m: nalgebra::DMatrix<f64>,
    e: Vec<f64>,
    mdot_u: Vec<f64>,
    g: Vec<f64>,
}

impl ArmReactions {
    /// The block for `arm` with actuators `acts` (forces read in this order) and the lumped
    /// masses `springs` that hang on springs (their pin forces read from `pin_forces`).
    pub fn new(
        arm: Arc<PlanarArm>,
        acts: &[LinearActuator],
        springs: &[LumpedMass],
        inputs: ReactionInputs,
    ) -> Result<Self, ParamError> {
        if inputs.forces.len() != acts.len() || springs.is_empty() == inputs.pin_forces.is_some() {
            return Err(ParamError::Shape {
                param: "reactions".into(),
                message: "one force signal per actuator and a pin-force signal exactly when masses hang on springs".into(),
            });
        }
        let acts = acts
            .iter()
            .map(|a| Ok((arm.resolve_pin(&a.a)?, arm.resolve_pin(&a.b)?)))
            .collect::<Result<Vec<_>, ParamError>>()?;
        let springs = springs
            .iter()
            .map(|m| match arm.resolve_pin(&m.pin)? {
                PinPoint::Station(s) => Ok((s, m.mass)),
                PinPoint::Ground(_) => Err(ParamError::Shape {
                    param: "lumped_masses".into(),
                    message: "a lumped mass must sit on a link".into(),
                }),
            })
            .collect::<Result<_, ParamError>>()?;
        let (n, n_rho) = (arm.n(), 2 * arm.n_links());
        let last = arm.n_links() - 1;
        let tip = arm.station(last, arm.links()[last].length())?;
        Ok(Self {
            tip,
            ws: RefCell::new(Workspace {
                frames: arm.frames(),
                q: vec![0.0; n],
                u: vec![0.0; n],
                udot: vec![0.0; n],
                act_forces: vec![Vector2::zeros(); acts.len()],
                rho: vec![0.0; n_rho],
                rho_paper: vec![0.0; n_rho],
                all: vec![0.0; if inputs.base.is_some() { n_rho } else { 0 }],
                m: if inputs.base.is_some() {
                    nalgebra::DMatrix::zeros(n, n)
                } else {
                    nalgebra::DMatrix::zeros(0, 0)
                },
                e: vec![0.0; n],
                mdot_u: vec![0.0; n],
                g: vec![0.0; n],
            }),
            arm,
            inputs,
            acts,
            springs,
            paper: false,
        })
    }

    /// Also publish `rho{k}_paper`. Without lumped masses on springs (rigid or none) the
    /// masses already move with their pins, so the two variants are the same.
    #[must_use]
    pub fn with_paper_variant(mut self, on: bool) -> Self {
        self.paper = on;
        self
    }

    fn n_rho(&self) -> usize {
        2 * self.arm.n_links()
    }
}

impl Element for ArmReactions {
    fn kind(&self) -> &str {
        "manipulator.reactions"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.inputs.signal_specs(self.arm.n(), self.springs.len())
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        let mut out: Vec<SignalSpec> = (1..=self.n_rho())
            .map(|k| SignalSpec::scalar(&format!("rho{k}")))
            .collect();
        if self.paper {
            out.extend((1..=self.n_rho()).map(|k| SignalSpec::scalar(&format!("rho{k}_paper"))));
        }
        if self.inputs.base.is_some() {
            out.extend(["F_ped_x", "F_ped_y", "M_ped"].map(SignalSpec::scalar));
        }
        out
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let mut ws = self.ws.borrow_mut();
        let Workspace {
            frames,
            q,
            u,
            udot,
            act_forces,
            rho,
            rho_paper,
            all,
            m,
            e,
            mdot_u,
            g,
        } = &mut *ws;
        q.copy_from_slice(io.input(0));
        u.copy_from_slice(io.input(1));
        udot.copy_from_slice(io.input(2));
        let first_base = 3 + self.acts.len() + usize::from(self.inputs.pin_forces.is_some());
        let field = self.inputs.base.as_ref().map(|_| {
            // absolute speeds: the base's roll is a turn of joint 1
            u[0] += io.u(first_base);
            udot[0] += io.u(first_base + 1);
            nalgebra::Vector2::new(io.u(first_base + 2), io.u(first_base + 3))
        });
        let kin = ArmKinematics::new(self.arm.pose_in(q, frames));
        let pose = kin.pose();
        for (c, (a, b)) in self.acts.iter().enumerate() {
            let d = pose.pin_point_position(b) - pose.pin_point_position(a);
            act_forces[c] = io.u(3 + c) * d / d.norm();
        }
        // +F e on pin b, −F e on pin a
        let act_loads = || {
            self.acts
                .iter()
                .zip(act_forces.iter())
                .flat_map(|((a, b), f)| {
                    [(b.station(), *f), (a.station(), -f)]
                        .into_iter()
                        .filter_map(|(s, f)| s.map(|s| (s, f)))
                })
        };
        let first_tip = first_base + 4 * usize::from(self.inputs.base.is_some());
        let tip_load = self.inputs.tip_load.as_ref().map(|_| {
            (
                &self.tip,
                Vector2::new(io.u(first_tip), io.u(first_tip + 1)),
            )
        });
        let pin_forces = self
            .inputs
            .pin_forces
            .as_ref()
            .map_or(&[][..], |_| io.input(3 + self.acts.len()));
        let spring_loads = self
            .springs
            .iter()
            .enumerate()
            .map(|(k, (s, _))| (s, Vector2::new(pin_forces[2 * k], pin_forces[2 * k + 1])));
        let weight = field.map_or(Vector2::new(0.0, self.arm.gravity()), |f| -f);
        kin.reactions_in_field_into(
            u,
            udot,
            act_loads().chain(spring_loads).chain(tip_load),
            &[],
            weight,
            rho,
        );
        if self.paper {
            if self.springs.is_empty() {
                rho_paper.copy_from_slice(rho);
            } else {
                kin.reactions_in_field_into(
                    u,
                    udot,
                    act_loads().chain(tip_load),
                    &self.springs,
                    weight,
                    rho_paper,
                );
            }
        }
        let pedestal = field.map(|f| {
            // the force on the whole arm from the vessel: Σ m (a − f), frame 0
            kin.reactions_in_field_into(u, udot, std::iter::empty(), &[], weight, all);
            let mut force = kin.pose().to_base(0, &Vector2::new(all[0], all[1]));
            // less the wire's pull: the rest comes from the vessel
            g.fill(0.0);
            if let Some((s, f)) = tip_load {
                force -= f;
                kin.pose().add_point_force(s, &f, g);
            }
            let wire_moment = g[0];
            // the moment about joint 1: Q₁ = (M u̇_a + Ṁ u_a − E(u_a))₁ − G(q; f)₁
            kin.mass_matrix_into(m);
            kin.kinetic_terms_into(u, e, Some(mdot_u));
            kin.field_forces_into(&f, g);
            let m_u: f64 = (0..u.len()).map(|k| m[(0, k)] * udot[k]).sum();
            let moment = m_u + mdot_u[0] - e[0] - g[0] - wire_moment;
            [-force.x, -force.y, -moment]
        });
        drop(kin);
        if let Some(ped) = pedestal {
            let first = self.n_rho() * if self.paper { 2 } else { 1 };
            for (k, v) in ped.into_iter().enumerate() {
                io.set_y(first + k, 0, v);
            }
        }
        for (k, r) in rho.iter().enumerate() {
            io.set_y(k, 0, *r);
        }
        if self.paper {
            for (k, r) in rho_paper.iter().enumerate() {
                io.set_y(self.n_rho() + k, 0, *r);
            }
        }
    }
}
