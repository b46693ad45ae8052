//! Section forces by force summation: the free body of everything beyond the section — the
//! rest of the link, with its distributed inertia, rotary inertia and gravity, its point
//! masses, the pin loads on it (cylinder forces, spring forces of lumped masses), and, at its
//! far end, the force and torque of the next joint (the reaction ρ of eq. 97 of everything
//! outboard, and the joint's torque). Exact for the model's loads: only internal forces
//! (strain, modal damping) are left out, and those are what the section carries.
//!
//! With the d'Alembert load per length `q = ρA (g⃗ − a)` and couple `μ = −ρI (Ω̇ + θ̈)`, both
//! in the axes of the link's frame, the part beyond x exerts on the part before it
//!
//! ```text
//! F(x) = F_far + ∫_x^L q ds + Σ_{x_k > x} f_k
//! M(x) = C_far + (r_far − r(x)) × F_far + ∫_x^L [(r(s) − r(x)) × q + μ] ds + Σ_{x_k > x} …
//! ```
//!
//! with r(s) = (s, w(s)) on the deformed axis; N = F_x, V = −F_y
//! (the convention of [`stress`](crate::stress)). A load exactly at the section counts as
//! before it: the values are the limits from beyond.
//!
//! The integrals run from the tip inwards over the grid's intervals, each cut into pieces of
//! at most L/max(16, 2·modes) with a 12-point Gauss–Legendre rule (the integrand is a sum of
//! sines of the modes: exact to rounding for sine modes up to 64).

use nalgebra::Vector2;

use crate::arm::Station;
use crate::kinematics::ArmKinematics;
use crate::quadrature::GaussLegendre;
use crate::stress::modal::modal_moment;
use crate::PlanarArm;
use bondgraph::ParamError;

/// Gauss–Legendre points per piece.
const POINTS_PER_PIECE: usize = 12;

/// A mass point of the free body: a quadrature point (weight × ρA, ρI) or a point mass.
#[derive(Clone, Debug)]
struct MassPoint {
    station: Station,
    mass: f64,
    inertia: f64,
}

/// The sections of one link at which to recover N, V, M, with everything that does not
/// depend on the configuration precomputed (stations, quadrature, mode curvatures).
#[derive(Clone, Debug)]
pub struct SectionGrid {
    link: usize,
    length: f64,
    xs: Vec<f64>,
    stations: Vec<Station>,
    /// ψ''_k(x) at each x, and EI(x).
    curvature: Vec<Vec<f64>>,
    ei: Vec<f64>,
    /// Mass points in (x_j, x_{j+1}] (the last interval ends at L), per interval.
    intervals: Vec<Vec<MassPoint>>,
}

/// N, V, M (summed) and the modal moment EI·w'' at the grid's sections.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SectionForces {
    /// Axial force (N), tension positive.
    pub n: Vec<f64>,
    /// Shear force (N).
    pub v: Vec<f64>,
    /// Bending moment by force summation (N·m).
    pub m: Vec<f64>,
    /// Bending moment EI·w''(x) of the assumed modes (N·m).
    pub m_modal: Vec<f64>,
    /// Slope w'(x) of the deformed axis (for dM/dx = V + w'N − μ).
    pub slope: Vec<f64>,
}

impl SectionForces {
    fn with_len(n: usize) -> Self {
        Self {
            n: vec![0.0; n],
            v: vec![0.0; n],
            m: vec![0.0; n],
            m_modal: vec![0.0; n],
            slope: vec![0.0; n],
        }
    }
}

impl SectionGrid {
    /// Sections of link `link` (0-based) at `xs` (strictly increasing, within [0, L]).
    pub fn new(arm: &PlanarArm, link: usize, xs: &[f64]) -> Result<Self, ParamError> {
        let l = arm.links().get(link).ok_or_else(|| {
            ParamError::shape("stress", format!("link {} does not exist", link + 1))
        })?;
        if l.geometric_stiffening() {
            return Err(ParamError::shape(
                "stress",
                format!(
                    "link {}: stress recovery does not follow the axial shortening of geometric_stiffening",
                    link + 1
                ),
            ));
        }
        let length = l.length();
        if xs.is_empty() || xs.windows(2).any(|w| w[1] <= w[0]) {
            return Err(ParamError::shape(
                "stress",
                "sections must be given at increasing x",
            ));
        }
        for &x in xs {
            if !(x.is_finite() && (0.0..=length).contains(&x)) {
                return Err(ParamError::invalid("x", x, "on the link, 0 <= x <= L"));
            }
        }
        let stations: Vec<Station> = xs.iter().map(|&x| arm.station_unchecked(link, x)).collect();
        let curvature = xs
            .iter()
            .map(|&x| l.modes().iter().map(|m| m.curvature(x)).collect())
            .collect();
        let ei = xs.iter().map(|&x| l.bending_stiffness_at(x)).collect();
        let rule = GaussLegendre::new(POINTS_PER_PIECE)?;
        let max_piece = length / (16.0_f64).max(2.0 * l.modes().len() as f64);
        let mut intervals = Vec::with_capacity(xs.len());
        for (j, &a) in xs.iter().enumerate() {
            let b = xs.get(j + 1).copied().unwrap_or(length);
            let mut pts = Vec::new();
            if b > a && l.has_distributed_mass() {
                let pieces = ((b - a) / max_piece).ceil().max(1.0) as usize;
                let h = (b - a) / pieces as f64;
                for p in 0..pieces {
                    let start = a + p as f64 * h;
                    for (s, w) in rule.on(h) {
                        let x = start + s;
                        pts.push(MassPoint {
                            station: arm.station_unchecked(link, x),
                            mass: w * l.mass_per_length_at(x),
                            inertia: w * l.rotary_inertia_per_length_at(x),
                        });
                    }
                }
            }
            for pm in l.point_masses() {
                let last = j + 1 == xs.len();
                if pm.x > a && (pm.x <= b || last) {
                    pts.push(MassPoint {
                        station: arm.station_unchecked(link, pm.x),
                        mass: pm.mass,
                        inertia: pm.inertia,
                    });
                }
            }
            intervals.push(pts);
        }
        Ok(Self {
            link,
            length,
            xs: xs.to_vec(),
            stations,
            curvature,
            ei,
            intervals,
        })
    }

    /// The link (0-based).
    #[must_use]
    pub fn link(&self) -> usize {
        self.link
    }
    /// The sections' x (m).
    #[must_use]
    pub fn xs(&self) -> &[f64] {
        &self.xs
    }
    /// Chord length L (m).
    #[must_use]
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Room for the results.
    #[must_use]
    pub fn forces(&self) -> SectionForces {
        SectionForces::with_len(self.xs.len())
    }

    /// Index of the interval (x_j, x_{j+1}] holding a load at x, or `None` if it is not beyond
    /// the first section.
    fn interval_of(&self, x: f64) -> Option<usize> {
        if x <= self.xs[0] {
            return None;
        }
        // the last j with x_j < x
        Some(self.xs.partition_point(|&a| a < x) - 1)
    }
}

/// `a × b` of plane vectors (its z component).
fn cross(a: &Vector2<f64>, b: &Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

impl ArmKinematics<'_> {
    /// Section forces of `grid`'s link at speeds `u`, accelerations `u_dot`, with the pin
    /// `loads` (station, force in frame 0) and the generalized forces of the joints
    /// `joint_torques` (one per joint: the torque on the outboard body of each, e.g. −D u of
    /// joint damping; empty: none), into `out` (from [`SectionGrid::forces`]).
    pub fn section_forces_into(
        &self,
        grid: &SectionGrid,
        u: &[f64],
        u_dot: &[f64],
        loads: &[(&Station, Vector2<f64>)],
        joint_torques: &[f64],
        out: &mut SectionForces,
    ) {
        let arm = self.arm();
        let i = grid.link;
        let pose = self.pose();
        let g0 = Vector2::new(0.0, -arm.gravity());
        let gi = pose.to_frame(i, &g0);
        let omega_dot: f64 = u_dot.iter().take(i + 1).sum();
        let (_, udb) = self.modal(i, u_dot);
        // The far end: the force of the next joint on link i (−ρ of joint i+1) and its torque.
        let (mut f, mut mo) = (Vector2::zeros(), 0.0);
        if i + 1 < arm.n_links() {
            let mut rho = vec![0.0; 2 * arm.n_links()];
            self.reactions_into(u, u_dot, loads.iter().map(|(s, f)| (*s, *f)), &[], &mut rho);
            let on_next = Vector2::new(rho[2 * (i + 1)], rho[2 * (i + 1) + 1]);
            let far = -pose.to_frame(i, &pose.to_base(i + 1, &on_next));
            let at = pose.to_frame(i, &(pose.origin(i + 1) - pose.origin(i)));
            f += far;
            mo += cross(&at, &far) - joint_torques.get(i + 1).copied().unwrap_or(0.0);
        }
        // Pin loads on link i, by interval.
        let add_point = |f: &mut Vector2<f64>, mo: &mut f64, j: usize| {
            for p in &grid.intervals[j] {
                let s = &p.station;
                let a = pose.to_frame(i, &self.point_acceleration(s, u, u_dot));
                let q = p.mass * (gi - a);
                let theta_ddot: f64 = s.theta.iter().zip(udb).map(|(t, x)| t * x).sum();
                *f += q;
                *mo += cross(&pose.local(s), &q) - p.inertia * (omega_dot + theta_ddot);
            }
            for (s, load) in loads {
                if s.link == i && grid.interval_of(s.x) == Some(j) {
                    let fl = pose.to_frame(i, load);
                    *f += fl;
                    *mo += cross(&pose.local(s), &fl);
                }
            }
        };
        for j in (0..grid.xs.len()).rev() {
            add_point(&mut f, &mut mo, j);
            let s = &grid.stations[j];
            let r = pose.local(s);
            out.n[j] = f.x;
            out.v[j] = -f.y;
            out.m[j] = mo - cross(&r, &f);
            out.m_modal[j] = modal_moment(grid.ei[j], &grid.curvature[j], pose.modal(i));
            out.slope[j] = pose.slope(s);
        }
    }

    /// The distributed load per length q = ρA (g⃗ − a) and couple μ = −ρI (Ω̇ + θ̈) at x on
    /// link `link`, in the axes of its frame (for checks of dV/dx = q_y).
    #[must_use]
    pub fn distributed_load(
        &self,
        link: usize,
        x: f64,
        u: &[f64],
        u_dot: &[f64],
    ) -> (Vector2<f64>, f64) {
        let arm = self.arm();
        let l = &arm.links()[link];
        let s = arm.station_unchecked(link, x);
        let pose = self.pose();
        let gi = pose.to_frame(link, &Vector2::new(0.0, -arm.gravity()));
        let a = pose.to_frame(link, &self.point_acceleration(&s, u, u_dot));
        let (_, udb) = self.modal(link, u_dot);
        let omega_dot: f64 = u_dot.iter().take(link + 1).sum();
        let theta_ddot: f64 = s.theta.iter().zip(udb).map(|(t, x)| t * x).sum();
        (
            l.mass_per_length_at(x) * (gi - a),
            -l.rotary_inertia_per_length_at(x) * (omega_dot + theta_ddot),
        )
    }
}
