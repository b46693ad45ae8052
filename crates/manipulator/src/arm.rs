//! [`PlanarArm`]: a planar serial chain of links joined by revolute joints, its generalized
//! coordinates, and its configuration ([`Pose`]) at given coordinates.
//!
//! # Generalized coordinates (eq. 32)
//! `q = [q_1 … q_{n_q}, q^{b1} …, q^{b n_q} …]`: first one chord-to-chord joint angle per
//! link, then the modal coordinates of each link in link order (a rigid link has none). The
//! knuckle boom (docs/knuckle-boom.md) has `q = [q1, q2, q3, qb1_1..3, qb2_1..3]`.
//!
//! # Frames
//! Frame 0 is inertial with gravity along −y₀. Frame i sits at joint i: at the origin of
//! frame 0 for i = 1, at the end of link i−1's chord otherwise; its x axis runs along link
//! i's chord at the angle `φ_i = q_1 + … + q_i` from x₀.

use std::cell::{Ref, RefCell};
use std::ops::Deref;

use nalgebra::Vector2;

use crate::joint::RevoluteJoint;
use crate::link::Link;
use crate::quadrature::GaussLegendre;
use crate::screw::{rot_z_cs, CoordinateTransform};
use crate::shape_integrals::ShapeIntegrals;
use bondgraph::ParamError;

/// A point on a link's axis at distance `x` along its chord, with the mode shapes evaluated
/// there (`ψ_k(x)`, `θ_k(x)`).
#[derive(Clone, Debug, PartialEq)]
pub struct Station {
    /// Link index, 0-based.
    pub link: usize,
    /// Distance along the chord (m).
    pub x: f64,
    pub(crate) psi: Vec<f64>,
    pub(crate) theta: Vec<f64>,
    /// With geometric stiffening: `S(x) = ∫₀ˣ ψ'ψ'ᵀ`, row-major m × m; else empty.
    pub(crate) shortening: Vec<f64>,
}

/// A planar serial manipulator.
#[derive(Clone, Debug)]
pub struct PlanarArm {
    links: Vec<Link>,
    joint: RevoluteJoint,
    gravity: f64,
    quadrature: GaussLegendre,
    modal_offset: Vec<usize>,
    n: usize,
    integrals: Vec<ShapeIntegrals>,
    /// Mass outboard of each link (kg).
    outboard: Vec<f64>,
    /// Whether any link keeps its axial shortening.
    stiffening: bool,
    /// The frames at the last configuration asked for with [`pose_in`](Self::pose_in): the
    /// elements of one arm all read the same q, so one of them computes them, the others read
    /// them in place.
    shared: RefCell<SharedFrames>,
}

/// [`Frames`] and the configuration they are at (compared bit for bit).
#[derive(Clone, Debug)]
struct SharedFrames {
    q: Vec<f64>,
    valid: bool,
    frames: Frames,
}

impl PlanarArm {
    /// A chain of `links` (at least one) under gravity `gravity` (m/s², along −y₀), with the
    /// default quadrature ([`GaussLegendre::DEFAULT_POINTS`] points per link).
    pub fn new(links: Vec<Link>, gravity: f64) -> Result<Self, ParamError> {
        Self::with_quadrature(links, gravity, GaussLegendre::DEFAULT_POINTS)
    }

    /// As [`new`](Self::new) with `points` Gauss–Legendre points per link: the rule of the
    /// per-station [`reference`](crate::reference), and at least the rule of the shape
    /// integrals of links whose modes are not sines ([`ShapeIntegrals::of`]).
    pub fn with_quadrature(
        links: Vec<Link>,
        gravity: f64,
        points: usize,
    ) -> Result<Self, ParamError> {
        if links.is_empty() {
            return Err(ParamError::shape("links", "an arm needs at least one link"));
        }
        ParamError::finite("gravity", gravity)?;
        if let Some(k) = links[..links.len() - 1].iter().position(Link::has_free_end) {
            return Err(ParamError::shape(
                "links",
                format!(
                    "link {} has cantilever modes, which move the end of its chord: only the last link may (the next joint sits on the chord's end)",
                    k + 1
                ),
            ));
        }
        let quadrature = GaussLegendre::new(points)?;
        let mut modal_offset = Vec::with_capacity(links.len());
        let mut n = links.len();
        for l in &links {
            modal_offset.push(n);
            n += l.modes().len();
        }
        let integrals = links
            .iter()
            .map(|l| ShapeIntegrals::of(l, points))
            .collect::<Result<Vec<_>, _>>()?;
        let outboard = (0..links.len())
            .map(|i| links[i + 1..].iter().map(Link::mass).sum())
            .collect();
        let stiffening = links.iter().any(Link::geometric_stiffening);
        let shared = RefCell::new(SharedFrames {
            q: Vec::with_capacity(n),
            valid: false,
            frames: Frames::with_room(links.len()),
        });
        Ok(Self {
            links,
            joint: RevoluteJoint,
            gravity,
            quadrature,
            modal_offset,
            n,
            integrals,
            outboard,
            stiffening,
            shared,
        })
    }

    /// Number of generalized coordinates n.
    #[must_use]
    pub fn n(&self) -> usize {
        self.n
    }
    /// Number of links (= joints).
    #[must_use]
    pub fn n_links(&self) -> usize {
        self.links.len()
    }
    /// The links.
    #[must_use]
    pub fn links(&self) -> &[Link] {
        &self.links
    }
    /// The joints' common description.
    #[must_use]
    pub fn joint(&self) -> &RevoluteJoint {
        &self.joint
    }
    /// Gravity (m/s², along −y₀).
    #[must_use]
    pub fn gravity(&self) -> f64 {
        self.gravity
    }
    /// The quadrature rule of the per-station reference.
    #[must_use]
    pub fn quadrature(&self) -> &GaussLegendre {
        &self.quadrature
    }
    /// Index in q of the first modal coordinate of link `i`.
    #[must_use]
    pub fn modal_offset(&self, i: usize) -> usize {
        self.modal_offset[i]
    }
    /// The shape integrals of link `i`.
    #[must_use]
    pub fn shape_integrals(&self, i: usize) -> &ShapeIntegrals {
        &self.integrals[i]
    }
    /// Mass outboard of link `i`: of the links after it (kg).
    #[must_use]
    pub fn outboard_mass(&self, i: usize) -> f64 {
        self.outboard[i]
    }
    /// Whether any link keeps its axial shortening (geometric stiffening).
    #[must_use]
    pub fn has_geometric_stiffening(&self) -> bool {
        self.stiffening
    }
    /// Total mass of the arm (kg).
    #[must_use]
    pub fn mass(&self) -> f64 {
        self.links.iter().map(Link::mass).sum()
    }

    /// A line of names for q: `q1.., qb1_1..` (1-based, as in docs/knuckle-boom.md).
    #[must_use]
    pub fn coordinate_names(&self) -> Vec<String> {
        let mut names: Vec<String> = (1..=self.links.len()).map(|i| format!("q{i}")).collect();
        for (i, l) in self.links.iter().enumerate() {
            names.extend((1..=l.modes().len()).map(|k| format!("qb{}_{k}", i + 1)));
        }
        names
    }

    /// The station at distance `x` along link `link`'s chord.
    pub fn station(&self, link: usize, x: f64) -> Result<Station, ParamError> {
        let l = self.links.get(link).ok_or_else(|| {
            ParamError::shape(
                "link",
                format!(
                    "link {} does not exist (the arm has {})",
                    link + 1,
                    self.links.len()
                ),
            )
        })?;
        if !(x.is_finite() && (0.0..=l.length()).contains(&x)) {
            return Err(ParamError::invalid("x", x, "on the link, 0 <= x <= L"));
        }
        Ok(self.station_unchecked(link, x))
    }

    pub(crate) fn station_unchecked(&self, link: usize, x: f64) -> Station {
        let l = &self.links[link];
        let modes = l.modes();
        Station {
            link,
            x,
            psi: modes.iter().map(|m| m.value(x)).collect(),
            theta: modes.iter().map(|m| m.slope(x)).collect(),
            shortening: if l.geometric_stiffening() {
                crate::geometric_stiffening::slope_products(modes, x)
            } else {
                Vec::new()
            },
        }
    }

    /// Frames with room for this arm's links (for [`pose_in`](Self::pose_in)).
    #[must_use]
    pub fn frames(&self) -> Frames {
        Frames::with_room(self.links.len())
    }

    /// The configuration at `q`.
    ///
    /// # Panics
    /// If `q.len() != self.n()`.
    #[must_use]
    pub fn pose<'a>(&'a self, q: &'a [f64]) -> Pose<'a> {
        let mut frames = self.frames();
        self.fill(q, &mut frames);
        Pose {
            arm: self,
            q,
            frames: PoseFrames::Owned(frames),
        }
    }

    /// The configuration at `q`: the arm's shared frames if they are at q (bit for bit), else
    /// computed there first; computed into `frames` only while a pose at another q still reads
    /// the shared ones. The same numbers as [`fill`](Self::fill) either way, and no
    /// allocation once `frames` has room (e.g. from [`frames`](Self::frames)).
    ///
    /// # Panics
    /// If `q.len() != self.n()`.
    #[must_use]
    pub fn pose_in<'a>(&'a self, q: &'a [f64], frames: &'a mut Frames) -> Pose<'a> {
        let frames = match self.shared_at(q) {
            Some(shared) => PoseFrames::Shared(shared),
            None => {
                self.fill(q, frames);
                PoseFrames::Borrowed(frames)
            }
        };
        Pose {
            arm: self,
            q,
            frames,
        }
    }

    /// The shared frames, at q; `None` if they are elsewhere and cannot be moved (a pose
    /// still reads them).
    fn shared_at(&self, q: &[f64]) -> Option<Ref<'_, Frames>> {
        if let Ok(shared) = self.shared.try_borrow() {
            if shared.is_at(q) {
                return Some(Ref::map(shared, |s| &s.frames));
            }
        }
        {
            let mut shared = self.shared.try_borrow_mut().ok()?;
            let SharedFrames {
                q: at,
                valid,
                frames,
            } = &mut *shared;
            *valid = false;
            self.fill(q, frames);
            at.clear();
            at.extend_from_slice(q);
            *valid = true;
        }
        let shared = self.shared.try_borrow().ok()?;
        Some(Ref::map(shared, |s| &s.frames))
    }

    fn fill(&self, q: &[f64], f: &mut Frames) {
        assert_eq!(
            q.len(),
            self.n,
            "q has {} entries, the arm {}",
            q.len(),
            self.n
        );
        f.phi.clear();
        f.cs.clear();
        f.origin.clear();
        f.shift.clear();
        f.chord.clear();
        let (mut a, mut o, mut shift) = (0.0, Vector2::zeros(), Vector2::zeros());
        for (i, link) in self.links.iter().enumerate() {
            a += q[i];
            let (s, c) = a.sin_cos();
            f.phi.push(a);
            f.cs.push((c, s));
            f.origin.push(o);
            o += link.length() * Vector2::new(c, s);
            if self.stiffening {
                f.shift.push(shift);
                if let Some(sh) = self.integrals[i].shortening() {
                    // s_i = −½ qᵀS(L)q: the chord end moves along the chord
                    let qb = &q[self.modal_offset[i]..self.modal_offset[i] + link.modes().len()];
                    let c_l = sh.chord();
                    let mut v = 0.0;
                    for (k, qk) in qb.iter().enumerate() {
                        for (m, qm) in qb.iter().enumerate() {
                            v += qk * c_l[(k, m)] * qm;
                        }
                    }
                    shift += -0.5 * v * Vector2::new(c, s);
                }
            }
        }
        f.origin.push(o);
        if self.stiffening {
            f.shift.push(shift);
        }
        // c_ij = R_0^i (o_i − o_j) for j ≤ i, row by row
        for (i, &(c, s)) in f.cs.iter().enumerate() {
            for j in 0..=i {
                let d = f.origin[i] - f.origin[j];
                f.chord
                    .push(Vector2::new(c * d.x + s * d.y, -s * d.x + c * d.y));
            }
        }
    }
}

impl SharedFrames {
    fn is_at(&self, q: &[f64]) -> bool {
        self.valid && crate::elements::same_bits(&self.q, q)
    }
}

/// The frames of an arm at one configuration: chord angles φ_i, their cosines and sines,
/// and the joint positions. A [`Pose`] owns or borrows them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frames {
    phi: Vec<f64>,
    /// (cos φ_i, sin φ_i)
    cs: Vec<(f64, f64)>,
    origin: Vec<Vector2<f64>>,
    /// With geometric stiffening: `o'_i − o_i = Σ_{j<i} s_j e_j`, the displacement of joint i
    /// by the shortening of the chords before it; else empty.
    shift: Vec<Vector2<f64>>,
    /// The chord offsets `c_j = R_0^i (o_i − o_j)`, j ≤ i, at `i (i + 1) / 2 + j`.
    chord: Vec<Vector2<f64>>,
}

impl Frames {
    /// Room for `nl` links.
    fn with_room(nl: usize) -> Self {
        Self {
            phi: Vec::with_capacity(nl),
            cs: Vec::with_capacity(nl),
            origin: Vec::with_capacity(nl + 1),
            shift: Vec::with_capacity(nl + 1),
            chord: Vec::with_capacity(nl * (nl + 1) / 2),
        }
    }
}

/// The arm at one configuration q: chord angles, joint positions, deflections.
#[derive(Clone, Debug)]
pub struct Pose<'a> {
    arm: &'a PlanarArm,
    q: &'a [f64],
    frames: PoseFrames<'a>,
}

/// The frames a [`Pose`] reads: its own, a caller's, or the arm's shared ones.
#[derive(Debug)]
enum PoseFrames<'a> {
    Owned(Frames),
    Borrowed(&'a Frames),
    Shared(Ref<'a, Frames>),
}

impl Clone for PoseFrames<'_> {
    fn clone(&self) -> Self {
        match self {
            Self::Owned(f) => Self::Owned(f.clone()),
            Self::Borrowed(f) => Self::Borrowed(f),
            Self::Shared(f) => Self::Shared(Ref::clone(f)),
        }
    }
}

impl Deref for PoseFrames<'_> {
    type Target = Frames;
    #[inline(always)]
    fn deref(&self) -> &Frames {
        match self {
            Self::Owned(f) => f,
            Self::Borrowed(f) => f,
            Self::Shared(f) => f,
        }
    }
}

impl<'a> Pose<'a> {
    /// The arm.
    #[must_use]
    pub fn arm(&self) -> &'a PlanarArm {
        self.arm
    }
    /// The coordinates.
    #[must_use]
    pub fn q(&self) -> &[f64] {
        self.q
    }
    /// Angle φ_i of link i's chord from x₀.
    #[must_use]
    pub fn chord_angle(&self, i: usize) -> f64 {
        self.frames.phi[i]
    }
    /// `R_i^0 v`: a vector in the coordinates of frame i expressed in frame 0.
    #[must_use]
    #[inline]
    pub fn to_base(&self, i: usize, v: &Vector2<f64>) -> Vector2<f64> {
        let (c, s) = self.frames.cs[i];
        Vector2::new(c * v.x - s * v.y, s * v.x + c * v.y)
    }
    /// `R_0^i v`: a vector in frame 0 expressed in the coordinates of frame i.
    #[must_use]
    #[inline]
    pub fn to_frame(&self, i: usize, v: &Vector2<f64>) -> Vector2<f64> {
        let (c, s) = self.frames.cs[i];
        Vector2::new(c * v.x + s * v.y, -s * v.x + c * v.y)
    }
    /// `R̄_0^i` (eq. 11): screws from frame 0 into the coordinates of frame i.
    #[must_use]
    pub fn screw_to_frame(&self, i: usize) -> CoordinateTransform {
        let (c, s) = self.frames.cs[i];
        CoordinateTransform::new(rot_z_cs(c, -s))
    }
    /// `R̄_i^0` (eq. 11): screws from the coordinates of frame i into frame 0.
    #[must_use]
    pub fn screw_to_base(&self, i: usize) -> CoordinateTransform {
        let (c, s) = self.frames.cs[i];
        CoordinateTransform::new(rot_z_cs(c, s))
    }
    /// `(cos, sin)` of the rotation `R_j^i` from frame j to frame i (angle φ_j − φ_i).
    #[must_use]
    pub fn relative_rotation(&self, j: usize, i: usize) -> (f64, f64) {
        let ((cj, sj), (ci, si)) = (self.frames.cs[j], self.frames.cs[i]);
        (cj * ci + sj * si, sj * ci - cj * si)
    }
    /// Position of joint i (origin of frame i) in frame 0; `origin(n_links)` is the end of
    /// the last chord.
    #[must_use]
    #[inline]
    pub fn origin(&self, i: usize) -> Vector2<f64> {
        self.frames.origin[i]
    }
    /// Position of joint i in frame 0 with the chords shortened by bending
    /// ([`geometric_stiffening`](crate::geometric_stiffening)): `o_i + Σ_{j<i} s_j e_j`; the
    /// paper's [`origin`](Self::origin) without it. Pins turn about these points.
    #[must_use]
    #[inline]
    pub fn pivot(&self, i: usize) -> Vector2<f64> {
        match self.frames.shift.get(i) {
            Some(d) => self.frames.origin[i] + d,
            None => self.frames.origin[i],
        }
    }
    /// The modal coordinates of link i.
    #[must_use]
    pub fn modal(&self, i: usize) -> &[f64] {
        let o = self.arm.modal_offset[i];
        &self.q[o..o + self.arm.links[i].modes().len()]
    }
    /// Deflection `w(x)` at a station.
    #[must_use]
    pub fn deflection(&self, s: &Station) -> f64 {
        s.psi
            .iter()
            .zip(self.modal(s.link))
            .map(|(p, q)| p * q)
            .sum()
    }
    /// Rotation `θ(x) = w'(x)` of the cross-section at a station.
    #[must_use]
    pub fn slope(&self, s: &Station) -> f64 {
        s.theta
            .iter()
            .zip(self.modal(s.link))
            .map(|(p, q)| p * q)
            .sum()
    }
    /// Position of a station in its link's frame: `(x, w(x))`, or `(x + u(x), w(x))` with the
    /// axial shortening u of geometric stiffening.
    #[must_use]
    pub fn local(&self, s: &Station) -> Vector2<f64> {
        if s.shortening.is_empty() {
            Vector2::new(s.x, self.deflection(s))
        } else {
            Vector2::new(s.x + self.axial_shortening(s), self.deflection(s))
        }
    }
    /// Position of a station in frame 0.
    #[must_use]
    pub fn position(&self, s: &Station) -> Vector2<f64> {
        self.pivot(s.link) + self.to_base(s.link, &self.local(s))
    }
    /// `(cos φ_i, sin φ_i)`.
    #[must_use]
    #[inline]
    pub fn cos_sin(&self, i: usize) -> (f64, f64) {
        self.frames.cs[i]
    }
    /// `c_j = R_0^i (o_i − o_j)`: joint i seen from joint j, in the coordinates of frame i
    /// (zero for j = i). The moment arm of a point r of link i about joint j is
    /// `d_j = c_j + (x, w)` (eq. 35).
    #[must_use]
    #[inline(always)]
    pub fn chord_offset(&self, i: usize, j: usize) -> Vector2<f64> {
        if j <= i {
            self.frames.chord[i * (i + 1) / 2 + j]
        } else {
            self.to_frame(i, &(self.frames.origin[i] - self.frames.origin[j]))
        }
    }
    /// The non-zero columns of the velocity Jacobian `∂r/∂q` of a station in frame 0 (rows
    /// `N_c` of eq. 72–73): `ẑ × (r − o_j)` for the joints j ≤ i of its link i, then
    /// `ψ_k R_i ŷ` for the link's modes; `column(k, ∂r/∂q_k)` for each.
    pub fn point_jacobian(&self, s: &Station, mut column: impl FnMut(usize, Vector2<f64>)) {
        let i = s.link;
        let r = self.position(s);
        for j in 0..=i {
            column(j, z_cross(&(r - self.pivot(j))));
        }
        let (c, sn) = self.frames.cs[i];
        let o = self.arm.modal_offset[i];
        if s.shortening.is_empty() {
            for (k, psi) in s.psi.iter().enumerate() {
                column(o + k, Vector2::new(-sn * psi, c * psi));
            }
        } else {
            // one column per coordinate (callers may assign): ψ_k n_i − (S(x)q)_k e_i
            let q = self.modal(i);
            let m = q.len();
            for (k, psi) in s.psi.iter().enumerate() {
                let sq: f64 = (0..m).map(|l| s.shortening[k * m + l] * q[l]).sum();
                column(o + k, Vector2::new(-sn * psi - sq * c, c * psi - sq * sn));
            }
        }
        if self.arm.stiffening {
            self.shortening_columns_of(s, false, column);
        }
    }
    /// `out += (∂r/∂q)ᵀ f`: the generalized force of a force `f` (frame 0) at a station
    /// (eq. 49).
    pub fn add_point_force(&self, s: &Station, f: &Vector2<f64>, out: &mut [f64]) {
        self.point_jacobian(s, |k, col| out[k] += col.dot(f));
    }
}

/// `ẑ × v` for a planar vector.
#[must_use]
pub(crate) fn z_cross(v: &Vector2<f64>) -> Vector2<f64> {
    Vector2::new(-v.y, v.x)
}

#[cfg(test)]
mod tests;
