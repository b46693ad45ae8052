//! The stress block: section forces and outer-fibre stresses as signals, evaluated only for
//! the output rows that read them (nothing in the right-hand side reads them).
//!
//! Reads what the reaction block reads — the I-field's `q`, `u`, `udot`, the cylinder forces
//! and the lumped masses' pin forces — and publishes, for each requested section (link k,
//! x), `link{k}.N(x={x})`, `V`, `M`, `M_modal` and, with a declared cross-section,
//! `sigma_top`, `sigma_bottom` (x written as Rust prints the f64: `4`, `6.5`); and with a
//! grid of P points per link, the vectors `grid{k}.N`, `grid{k}.V`, … of P entries at
//! x_j = L·j/(P−1) (what `bg-sim stress` reads).

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{CausalRule, Element, Io, ParamError, Ports, SignalSpec};
use nalgebra::Vector2;

use crate::actuator::LinearActuator;
use crate::arm::{Frames, PlanarArm, Station};
use crate::kinematics::ArmKinematics;
use crate::lumped_mass::LumpedMass;
use crate::pin::PinPoint;
use crate::stress::section::CrossSection;
use crate::stress::summation::{SectionForces, SectionGrid};

/// Signals the block reads (as [`ReactionInputs`](crate::elements::ReactionInputs)).
pub type StressInputs = crate::elements::ReactionInputs;

/// The quantities published per section, in this order.
pub const QUANTITIES: [&str; 6] = ["N", "V", "M", "M_modal", "sigma_top", "sigma_bottom"];

/// One link's sections: the grid, where each published output reads from, the section.
#[derive(Debug)]
struct LinkSections {
    grid: SectionGrid,
    section: Option<CrossSection>,
    /// (index in the grid) of each requested station, in request order.
    stations: Vec<usize>,
    /// Grid points (indices in the grid) of the equally spaced grid, if any.
    spaced: Vec<usize>,
    forces: SectionForces,
}

/// The stress block of a [`PlanarArm`].
#[derive(Debug)]
pub struct ArmStress {
    arm: Arc<PlanarArm>,
    inputs: StressInputs,
    acts: Vec<(PinPoint, PinPoint)>,
    springs: Vec<Station>,
    /// Joint damping (the first n_links entries of D): the joint torques are −D u.
    joint_damping: Vec<f64>,
    links: Vec<LinkSections>,
    /// Requested stations (link, x), in order, for the output names.
    requested: Vec<(usize, f64)>,
    ws: RefCell<Workspace>,
}

#[derive(Debug)]
struct Workspace {
    frames: Frames,
    q: Vec<f64>,
    u: Vec<f64>,
    udot: Vec<f64>,
    torques: Vec<f64>,
}

/// The name of a station's output: `link1.M(x=4)`.
#[must_use]
pub fn station_signal(link: usize, quantity: &str, x: f64) -> String {
    format!("link{}.{quantity}(x={x})", link + 1)
}

impl ArmStress {
    /// The block for `arm` with actuators `acts` (forces read in this order), lumped masses
    /// on springs `springs`, joint damping `joint_damping` (one per joint), the links'
    /// cross-sections `sections` (one per link, `None`: no stresses), the requested
    /// `stations` (link 0-based, x) and `grid` equally spaced points per link with distributed
    /// mass or a section (0: none).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        arm: Arc<PlanarArm>,
        acts: &[LinearActuator],
        springs: &[LumpedMass],
        joint_damping: Vec<f64>,
        sections: &[Option<CrossSection>],
        stations: &[(usize, f64)],
        grid: usize,
        inputs: StressInputs,
    ) -> Result<Self, ParamError> {
        let nl = arm.n_links();
        if grid == 1 {
            return Err(ParamError::shape(
                "stress_grid",
                "needs at least 2 points (or 0: none)",
            ));
        }
        let acts = acts
            .iter()
            .map(|a| Ok((arm.resolve_pin(&a.a)?, arm.resolve_pin(&a.b)?)))
            .collect::<Result<Vec<_>, ParamError>>()?;
        let springs = springs
            .iter()
            .map(|m| match arm.resolve_pin(&m.pin)? {
                PinPoint::Station(s) => Ok(s),
                PinPoint::Ground(_) => Err(ParamError::shape(
                    "lumped_masses",
                    "a lumped mass must sit on a link",
                )),
            })
            .collect::<Result<_, ParamError>>()?;
        let mut links = Vec::new();
        for i in 0..nl {
            let l = &arm.links()[i];
            let section = sections.get(i).cloned().flatten();
            let on_grid = grid >= 2 && (l.has_distributed_mass() || section.is_some());
            let mut xs: Vec<f64> = stations
                .iter()
                .filter(|(k, _)| *k == i)
                .map(|(_, x)| *x)
                .collect();
            if on_grid {
                xs.extend((0..grid).map(|j| l.length() * j as f64 / (grid - 1) as f64));
            }
            if xs.is_empty() {
                continue;
            }
            for &x in &xs {
                if !(x.is_finite() && (0.0..=l.length()).contains(&x)) {
                    return Err(ParamError::shape(
                        "stress_at",
                        format!(
                            "link {}: x = {x} is not on the link (0 ≤ x ≤ L = {})",
                            i + 1,
                            l.length()
                        ),
                    ));
                }
            }
            let mut sorted = xs.clone();
            sorted.sort_by(f64::total_cmp);
            sorted.dedup();
            let index = |x: f64| sorted.partition_point(|&a| a < x);
            let station_idx = stations
                .iter()
                .filter(|(k, _)| *k == i)
                .map(|(_, x)| index(*x))
                .collect();
            let spaced = if on_grid {
                (0..grid)
                    .map(|j| index(l.length() * j as f64 / (grid - 1) as f64))
                    .collect()
            } else {
                Vec::new()
            };
            let grid = SectionGrid::new(&arm, i, &sorted)?;
            links.push(LinkSections {
                forces: grid.forces(),
                grid,
                section,
                stations: station_idx,
                spaced,
            });
        }
        if let Some((k, _)) = stations.iter().find(|(k, _)| *k >= nl) {
            return Err(ParamError::shape(
                "stress_at",
                format!("link {} does not exist (the arm has {nl})", k + 1),
            ));
        }
        let n = arm.n();
        Ok(Self {
            ws: RefCell::new(Workspace {
                frames: arm.frames(),
                q: vec![0.0; n],
                u: vec![0.0; n],
                udot: vec![0.0; n],
                torques: vec![0.0; nl],
            }),
            arm,
            inputs,
            acts,
            springs,
            joint_damping,
            links,
            requested: stations.to_vec(),
        })
    }

    fn link_sections(&self, link: usize) -> Option<&LinkSections> {
        self.links.iter().find(|l| l.grid.link() == link)
    }

    /// The published quantities of a link (σ only with a section).
    fn quantities(&self, link: usize) -> &'static [&'static str] {
        match self.link_sections(link).and_then(|l| l.section.as_ref()) {
            Some(_) => &QUANTITIES,
            None => &QUANTITIES[..4],
        }
    }
}

impl Element for ArmStress {
    fn kind(&self) -> &str {
        "manipulator.stress"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        // the reaction block's inputs (the scene refuses a base or a tip load with stress)
        self.inputs.signal_specs(self.arm.n(), self.springs.len())
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        let mut out = Vec::new();
        for &(k, x) in &self.requested {
            for q in self.quantities(k) {
                out.push(SignalSpec::scalar(&station_signal(k, q, x)));
            }
        }
        for l in &self.links {
            if l.spaced.is_empty() {
                continue;
            }
            out.push(SignalSpec {
                name: format!("grid{}.x", l.grid.link() + 1),
                dim: l.spaced.len(),
            });
            for q in self.quantities(l.grid.link()) {
                out.push(SignalSpec {
                    name: format!("grid{}.{q}", l.grid.link() + 1),
                    dim: l.spaced.len(),
                });
            }
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
            torques,
        } = &mut *ws;
        q.copy_from_slice(io.input(0));
        u.copy_from_slice(io.input(1));
        udot.copy_from_slice(io.input(2));
        for (j, t) in torques.iter_mut().enumerate() {
            *t = -self.joint_damping.get(j).copied().unwrap_or(0.0) * u[j];
        }
        let kin = ArmKinematics::new(self.arm.pose_in(q, frames));
        let pose = kin.pose();
        let mut loads: Vec<(&Station, Vector2<f64>)> = Vec::new();
        for (c, (a, b)) in self.acts.iter().enumerate() {
            let d = pose.pin_point_position(b) - pose.pin_point_position(a);
            let f = io.u(3 + c) * d / d.norm();
            if let Some(s) = b.station() {
                loads.push((s, f));
            }
            if let Some(s) = a.station() {
                loads.push((s, -f));
            }
        }
        if self.inputs.pin_forces.is_some() {
            let pf = io.input(3 + self.acts.len());
            for (k, s) in self.springs.iter().enumerate() {
                loads.push((s, Vector2::new(pf[2 * k], pf[2 * k + 1])));
            }
        }
        // Compute every link's sections (the block is evaluated only for rows that read it).
        let mut results: Vec<SectionForces> = Vec::with_capacity(self.links.len());
        for l in &self.links {
            let mut f = l.forces.clone();
            kin.section_forces_into(&l.grid, u, udot, &loads, torques, &mut f);
            results.push(f);
        }
        drop(kin);
        let value = |l: &LinkSections, f: &SectionForces, q: &str, j: usize| -> f64 {
            let x = l.grid.xs()[j];
            match q {
                "N" => f.n[j],
                "V" => f.v[j],
                "M" => f.m[j],
                "M_modal" => f.m_modal[j],
                "sigma_top" => l
                    .section
                    .as_ref()
                    .map_or(f64::NAN, |s| s.sigma_top(x, f.n[j], f.m[j])),
                _ => l
                    .section
                    .as_ref()
                    .map_or(f64::NAN, |s| s.sigma_bottom(x, f.n[j], f.m[j])),
            }
        };
        let mut y = 0;
        let mut seen = vec![0usize; self.arm.n_links()];
        for &(k, _) in &self.requested {
            let li = self.links.iter().position(|l| l.grid.link() == k);
            let Some(li) = li else { continue };
            let (l, f) = (&self.links[li], &results[li]);
            let j = l.stations[seen[k]];
            seen[k] += 1;
            for q in self.quantities(k) {
                io.set_y(y, 0, value(l, f, q, j));
                y += 1;
            }
        }
        for (l, f) in self.links.iter().zip(&results) {
            if l.spaced.is_empty() {
                continue;
            }
            for (c, &j) in l.spaced.iter().enumerate() {
                io.set_y(y, c, l.grid.xs()[j]);
            }
            y += 1;
            for q in self.quantities(l.grid.link()) {
                for (c, &j) in l.spaced.iter().enumerate() {
                    io.set_y(y, c, value(l, f, q, j));
                }
                y += 1;
            }
        }
    }
}
