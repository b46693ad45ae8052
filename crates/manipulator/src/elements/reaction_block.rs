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

use std::sync::Arc;

use bondgraph::{CausalRule, Element, Io, ParamError, Ports, SignalSpec};
use nalgebra::Vector2;

use crate::actuator::LinearActuator;
use crate::arm::{PlanarArm, Station};
use crate::lumped_mass::LumpedMass;
use crate::pin::Pin;
use crate::reactions::PointLoad;

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
}

/// The reaction-force block of a [`PlanarArm`].
#[derive(Debug)]
pub struct ArmReactions {
    arm: Arc<PlanarArm>,
    inputs: ReactionInputs,
    acts: Vec<(Option<Station>, Option<Station>, LinearActuator)>,
    springs: Vec<(Station, f64)>,
    paper: bool,
}

fn station(arm: &PlanarArm, pin: &Pin) -> Result<Option<Station>, ParamError> {
    match *pin {
        Pin::Ground(_) => Ok(None),
        Pin::Link { link, x } => Ok(Some(arm.station(link, x)?)),
    }
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
            .map(|a| Ok((station(&arm, &a.a)?, station(&arm, &a.b)?, *a)))
            .collect::<Result<_, ParamError>>()?;
        let springs = springs
            .iter()
            .map(|m| {
                Ok((
                    station(&arm, &m.pin)?.ok_or_else(|| ParamError::Shape {
                        param: "lumped_masses".into(),
                        message: "a lumped mass must sit on a link".into(),
                    })?,
                    m.mass,
                ))
            })
            .collect::<Result<_, ParamError>>()?;
        Ok(Self {
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
        let n = self.arm.n();
        let v = |name: &str, dim| SignalSpec {
            name: name.to_owned(),
            dim,
        };
        let mut s = vec![
            v(&self.inputs.q, n),
            v(&self.inputs.u, n),
            v(&self.inputs.udot, n),
        ];
        s.extend(self.inputs.forces.iter().map(|f| v(f, 1)));
        if let Some(p) = &self.inputs.pin_forces {
            s.push(v(p, 2 * self.springs.len()));
        }
        s
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        let mut out: Vec<SignalSpec> = (1..=self.n_rho())
            .map(|k| SignalSpec::scalar(&format!("rho{k}")))
            .collect();
        if self.paper {
            out.extend((1..=self.n_rho()).map(|k| SignalSpec::scalar(&format!("rho{k}_paper"))));
        }
        out
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let (q, u, udot) = (
            io.input(0).to_vec(),
            io.input(1).to_vec(),
            io.input(2).to_vec(),
        );
        let kin = self.arm.kinematics(&q);
        let pose = kin.pose();
        let mut loads = Vec::new();
        for (c, (sa, sb, act)) in self.acts.iter().enumerate() {
            let f = io.u(3 + c) * act.direction(pose);
            if let Some(s) = sb {
                loads.push(PointLoad {
                    station: s.clone(),
                    force: f,
                });
            }
            if let Some(s) = sa {
                loads.push(PointLoad {
                    station: s.clone(),
                    force: -f,
                });
            }
        }
        let n_act_loads = loads.len();
        if self.inputs.pin_forces.is_some() {
            let pf = io.input(3 + self.acts.len()).to_vec();
            for (k, (s, _)) in self.springs.iter().enumerate() {
                loads.push(PointLoad {
                    station: s.clone(),
                    force: Vector2::new(pf[2 * k], pf[2 * k + 1]),
                });
            }
        }
        let rho = kin.reactions(&u, &udot, &loads, &[]);
        for (k, r) in rho.iter().enumerate() {
            io.set_y(k, 0, *r);
        }
        if self.paper {
            let paper = if self.springs.is_empty() {
                rho.clone()
            } else {
                kin.reactions(&u, &udot, &loads[..n_act_loads], &self.springs)
            };
            for (k, r) in paper.iter().enumerate() {
                io.set_y(self.n_rho() + k, 0, *r);
            }
        }
    }
}
