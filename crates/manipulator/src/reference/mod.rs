//! The per-station reference: M (eq. 42), T (eq. 41), E (eq. 44), Ṁu, G and V_g (eqs.
//! 45–48), K (eq. 51) and the reactions (eq. 97) summed over the Gauss–Legendre points and
//! point masses of every link with the projection matrix of each station (eq. 38), as the
//! paper writes them.
//!
//! This is what the arm computed before its [`ShapeIntegrals`](crate::ShapeIntegrals): it
//! allocates and costs O(points × modes) per link, so it is not for the right-hand side. The
//! tests hold the Gram-matrix code ([`ArmKinematics`](crate::ArmKinematics)) to it.

mod gravity;
mod kinetic_forces;
mod mass_matrix;
mod reactions;

use nalgebra::DMatrix;

use crate::arm::{PlanarArm, Pose, Station};
use crate::projection::Projection;

/// A station carrying mass: a quadrature point of a link (mass `w·ρA`, rotary inertia `w·ρI`)
/// or a point mass.
#[derive(Clone, Debug)]
struct MassStation {
    station: Station,
    mass: f64,
    inertia: f64,
}

/// One mass-carrying station at a configuration: its projection and its inertia.
#[derive(Clone, Copy, Debug)]
struct MassPoint<'a> {
    projection: &'a Projection,
    /// Mass (kg): `w·ρA` for a quadrature point, `m` for a point mass.
    mass: f64,
    /// Rotary inertia about z (kg·m²): `w·ρI`, or a point mass's own.
    inertia: f64,
    /// The station (link, x, mode values).
    station: &'a Station,
}

/// The arm at configuration q with the projection matrix of each of its mass stations
/// (the arm's [`quadrature`](PlanarArm::quadrature) along every link).
#[derive(Clone, Debug)]
pub struct StationKinematics<'a> {
    pose: Pose<'a>,
    stations: Vec<MassStation>,
    projections: Vec<Projection>,
}

impl<'a> StationKinematics<'a> {
    /// Kinematics of `arm` at `q`.
    ///
    /// # Panics
    /// If `q.len() != arm.n()`.
    #[must_use]
    pub fn new(arm: &'a PlanarArm, q: &'a [f64]) -> Self {
        let pose = arm.pose(q);
        let mut stations = Vec::new();
        for (i, link) in arm.links().iter().enumerate() {
            if link.has_distributed_mass() {
                for (x, w) in arm.quadrature().on(link.length()) {
                    stations.push(MassStation {
                        station: arm.station_unchecked(i, x),
                        mass: w * link.mass_per_length_at(x),
                        inertia: w * link.rotary_inertia_per_length_at(x),
                    });
                }
            }
            for m in link.point_masses() {
                stations.push(MassStation {
                    station: arm.station_unchecked(i, m.x),
                    mass: m.mass,
                    inertia: m.inertia,
                });
            }
        }
        let projections = stations
            .iter()
            .map(|ms| Projection::at(&pose, &ms.station))
            .collect();
        Self {
            pose,
            stations,
            projections,
        }
    }

    /// The configuration.
    #[must_use]
    pub fn pose(&self) -> &Pose<'a> {
        &self.pose
    }
    /// The arm.
    #[must_use]
    pub fn arm(&self) -> &'a PlanarArm {
        self.pose.arm()
    }
    /// Every mass-carrying station with its projection.
    fn points(&self) -> impl Iterator<Item = MassPoint<'_>> {
        self.stations
            .iter()
            .zip(self.projections.iter())
            .map(|(ms, projection)| MassPoint {
                projection,
                mass: ms.mass,
                inertia: ms.inertia,
                station: &ms.station,
            })
    }
}

/// K of eq. 51 (n×n) by the arm's quadrature: `Σ_i E_iI_i Σ_points w ψ''ψ''ᵀ`.
#[must_use]
pub fn stiffness_matrix(arm: &PlanarArm) -> DMatrix<f64> {
    let n = arm.n();
    let mut k = DMatrix::zeros(n, n);
    for (i, link) in arm.links().iter().enumerate() {
        let o = arm.modal_offset(i);
        let modes = link.modes();
        for (x, w) in arm.quadrature().on(link.length()) {
            let c: Vec<f64> = modes.iter().map(|m| m.curvature(x)).collect();
            for a in 0..modes.len() {
                for b in 0..modes.len() {
                    k[(o + a, o + b)] += link.bending_stiffness_at(x) * w * c[a] * c[b];
                }
            }
        }
    }
    k
}
