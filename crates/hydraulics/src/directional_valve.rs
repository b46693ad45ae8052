//! 4/3 directional valve `hydraulics.directional_valve`: a proportional spool valve with four
//! hydraulic ports `P`, `T`, `A`, `B` (any supply: a pump line, an accumulator, a pipe) and a
//! choice of centre.
//!
//! The spool stroke x ∈ [−1, 1] (a signal, clamped) opens four metering edges, each an
//! orifice (Merritt, *Hydraulic Control Systems*, 1967, the four-way spool valve; Jelali &
//! Kroll, *Hydraulic Servo-systems*, 2003, for overlap and underlap):
//!
//! ```text
//! P→A, B→T:  Q = α·o₊(x)·regRoot(Δp)      o₊(x) = clamp((x − lap)/(1 − lap), 0, 1)
//! P→B, A→T:  Q = α·o₋(x)·regRoot(Δp)      o₋(x) = o₊(−x)
//! ```
//!
//! with Δp the drop along the edge and `lap = overlap − underlap` (fractions of the stroke):
//! an overlapped spool has a dead band |x| ≤ overlap with every edge shut; an underlapped one
//! has all four edges open by underlap/(1 + underlap) at x = 0 (the bridge that leaks from P
//! to T at centre). The centre type adds passages that are open in the middle and close as
//! the spool moves, with opening `c(x) = c₀·(1 − (x/x_c)²)²` for |x| < x_c (0 beyond; C¹):
//!
//! | `centre` | passages at x = 0 |
//! |---|---|
//! | `closed` | none (all ports blocked) |
//! | `open` | P→T, A→T, B→T (every port connected) |
//! | `tandem` | P→T (pump unloaded, A and B blocked) |
//! | `float` | A→T, B→T (P blocked, the actuator free) |
//!
//! Every edge also leaks laminarly, `g_leak·Δp` (the spool's radial clearance): at x = 0 a
//! closed-centre valve passes only these leaks. The flow into the valve at each port is the
//! sum over the edges that touch it, so `Q_P + Q_T + Q_A + Q_B = 0` exactly (volume
//! conserved), and since every edge's flow has the sign of its drop, the power
//! `Σ P_k·Q_k = Σ_edges Q·Δp ≥ 0` is dissipated. Swapping A and B and reversing the spool
//! gives the same flows (the valve is symmetric).
//!
//! **Spool dynamics** are not inside the element: feed `x_v` from the core's `lag` for a
//! first-order spool (`τ·ẋ_v = u − x_v`), or from two `lag`s in series for a second-order
//! (critically damped or slower) one.
//!
//! Causality: every port receives its pressure and sets its flow (conductance): attach each to
//! a 0-junction with a chamber (a hose volume) or to a pressure source.

use bondgraph::kind::{BuildError, Change, KindDecl, ParamDecl, Range, Simplification};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage,
};

use crate::orifice::{self, reg_root, reg_root_derivative};

/// What the middle position connects (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Centre {
    /// All ports blocked.
    Closed,
    /// Every port connected (P→T, A→T, B→T).
    Open,
    /// P→T, A and B blocked.
    Tandem,
    /// A→T and B→T, P blocked.
    Float,
}

impl Centre {
    /// The centre named `word` (`closed`, `open`, `tandem`, `float`).
    #[must_use]
    pub fn from_word(word: &str) -> Option<Self> {
        match word {
            "closed" => Some(Self::Closed),
            "open" => Some(Self::Open),
            "tandem" => Some(Self::Tandem),
            "float" => Some(Self::Float),
            _ => None,
        }
    }
}

const P: usize = 0;
const T: usize = 1;
const A: usize = 2;
const B: usize = 3;

/// One metering edge at a spool position: from, to, opening, d(opening)/dx, leak conductance.
#[derive(Clone, Copy, Debug, Default)]
struct Edge {
    from: usize,
    to: usize,
    opening: f64,
    slope: f64,
    leak: f64,
}

/// A 4/3 directional valve with ports `P`, `T`, `A`, `B`.
///
/// * `alpha` — orifice coefficient α of each metering edge at full opening, m³/(s·√Pa), > 0.
/// * `x_v` — spool stroke (dimensionless, may be modulated), clamped to [−1, 1].
/// * `overlap`, `underlap` — fractions of the stroke in [0, 1) (at most one nonzero).
/// * `centre`, `centre_area` (c₀, fraction of α, ≥ 0), `centre_stroke` (x_c, in (0, 1]).
/// * `g_leak` — leak conductance of each edge, m³/(s·Pa), ≥ 0.
/// * `p_tr` — regRoot transition pressure, Pa, ≥ 0.
#[derive(Debug)]
pub struct DirectionalValve {
    alpha: f64,
    x_v: Param,
    lap: f64,
    centre: Centre,
    centre_area: f64,
    centre_stroke: f64,
    g_leak: f64,
    p_tr: f64,
}

impl DirectionalValve {
    /// A closed-centre, zero-lap valve with coefficient `alpha` and spool `x_v`, edge leakage
    /// 1e-13 m³/(s·Pa), p_tr = 1e5 Pa; set the rest with the `with_*` methods.
    pub fn new(alpha: f64, x_v: impl Into<Param>) -> Result<Self, ParamError> {
        ParamError::positive("alpha", alpha)?;
        let x_v = x_v.into();
        if let Some(x) = x_v.constant() {
            ParamError::finite("x_v", x)?;
        }
        Ok(Self {
            alpha,
            x_v,
            lap: 0.0,
            centre: Centre::Closed,
            centre_area: 1.0,
            centre_stroke: 0.2,
            g_leak: 1e-13,
            p_tr: 1e5,
        })
    }

    /// Overlap (dead band) and underlap, fractions of the stroke in [0, 1), at most one > 0.
    pub fn with_lap(mut self, overlap: f64, underlap: f64) -> Result<Self, ParamError> {
        for (name, v) in [("overlap", overlap), ("underlap", underlap)] {
            if !(v.is_finite() && (0.0..1.0).contains(&v)) {
                return Err(ParamError::OutOfRange {
                    param: name.into(),
                    value: v,
                    requirement: "a fraction of the stroke in [0, 1)",
                });
            }
        }
        if overlap > 0.0 && underlap > 0.0 {
            return Err(ParamError::Shape {
                param: "underlap".into(),
                message: "a spool is overlapped or underlapped, not both: give one of them".into(),
            });
        }
        self.lap = overlap - underlap;
        Ok(self)
    }

    /// The centre type, the centre passages' area c₀ (fraction of α, ≥ 0) and the stroke x_c
    /// (in (0, 1]) at which they are shut.
    pub fn with_centre(
        mut self,
        centre: Centre,
        area: f64,
        stroke: f64,
    ) -> Result<Self, ParamError> {
        self.centre_area = ParamError::non_negative("centre_area", area)?;
        if !(stroke.is_finite() && stroke > 0.0 && stroke <= 1.0) {
            return Err(ParamError::OutOfRange {
                param: "centre_stroke".into(),
                value: stroke,
                requirement: "in (0, 1]",
            });
        }
        self.centre = centre;
        self.centre_stroke = stroke;
        Ok(self)
    }

    /// Leak conductance of each metering edge (m³/(s·Pa), ≥ 0) and the regRoot transition
    /// pressure (Pa, ≥ 0).
    pub fn with_leakage(mut self, g_leak: f64, p_tr: f64) -> Result<Self, ParamError> {
        self.g_leak = ParamError::non_negative("g_leak", g_leak)?;
        self.p_tr = ParamError::non_negative("p_tr", p_tr)?;
        Ok(self)
    }

    /// The metering edges at spool stroke `x_v` (not yet clamped); the slopes are with
    /// respect to x_v (0 outside [−1, 1]).
    fn edges(&self, x_v: f64) -> ([Edge; 7], usize) {
        let x = x_v.clamp(-1.0, 1.0);
        let dx = if (-1.0..=1.0).contains(&x_v) {
            1.0
        } else {
            0.0
        };
        let width = 1.0 - self.lap;
        // At a kink the slope is one-sided: at ξ = 0 the P→A side takes its opening slope and
        // the P→B side none, so at x_v = lap = 0 the partials are the right derivative.
        let side = |s: f64| {
            let xi = (s * x - self.lap) / width;
            if xi < 0.0 || (xi == 0.0 && s < 0.0) {
                (0.0, 0.0)
            } else if xi >= 1.0 {
                (1.0, 0.0)
            } else {
                (xi, s * dx / width)
            }
        };
        let ((op, sp), (om, sm)) = (side(1.0), side(-1.0));
        let g = self.g_leak;
        let mut e = [Edge::default(); 7];
        e[0] = Edge {
            from: P,
            to: A,
            opening: op,
            slope: sp,
            leak: g,
        };
        e[1] = Edge {
            from: B,
            to: T,
            opening: op,
            slope: sp,
            leak: g,
        };
        e[2] = Edge {
            from: P,
            to: B,
            opening: om,
            slope: sm,
            leak: g,
        };
        e[3] = Edge {
            from: A,
            to: T,
            opening: om,
            slope: sm,
            leak: g,
        };
        let mut n = 4;
        // centre passages: c₀·(1 − s²)², s = x/x_c
        let s = x / self.centre_stroke;
        let (c, dc) = if s.abs() < 1.0 {
            let u = 1.0 - s * s;
            (
                self.centre_area * u * u,
                -4.0 * self.centre_area * s * u / self.centre_stroke * dx,
            )
        } else {
            (0.0, 0.0)
        };
        let passages: &[(usize, usize)] = match self.centre {
            Centre::Closed => &[],
            Centre::Open => &[(P, T), (A, T), (B, T)],
            Centre::Tandem => &[(P, T)],
            Centre::Float => &[(A, T), (B, T)],
        };
        for &(from, to) in passages {
            e[n] = Edge {
                from,
                to,
                opening: c,
                slope: dc,
                leak: 0.0,
            };
            n += 1;
        }
        (e, n)
    }

    /// The flows *into* the valve at P, T, A, B for spool stroke `x_v` and port pressures
    /// `p` (P, T, A, B).
    #[must_use]
    pub fn flows(&self, x_v: f64, p: &[f64; 4]) -> [f64; 4] {
        let (edges, n) = self.edges(x_v);
        let mut q = [0.0; 4];
        for e in &edges[..n] {
            let dp = p[e.from] - p[e.to];
            let qe = self.alpha * e.opening * reg_root(dp, self.p_tr) + e.leak * dp;
            q[e.from] += qe;
            q[e.to] -= qe;
        }
        q
    }
}

impl Element for DirectionalValve {
    fn kind(&self) -> &str {
        "hydraulics.directional_valve"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(["P", "T", "A", "B"].map(|n| PortSpec::new(n, 1)).to_vec())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::FlowOut; 4]])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.x_v.signal_inputs()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let mut reads: Vec<Slot> = (0..4).map(Slot::Effort).collect();
        reads.extend((0..self.x_v.n_inputs()).map(Slot::Input));
        vec![Stage {
            writes: (0..4).map(Slot::Flow).collect(),
            reads,
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let p = [io.e(0, 0), io.e(1, 0), io.e(2, 0), io.e(3, 0)];
        let q = self.flows(self.x_v.value(io, 0), &p);
        for (k, qk) in q.into_iter().enumerate() {
            io.set_f_in(k, 0, qk);
        }
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let p = [io.e(0, 0), io.e(1, 0), io.e(2, 0), io.e(3, 0)];
        let (edges, n) = self.edges(self.x_v.value(io, 0));
        // ∂q_e/∂P_from = −∂q_e/∂P_to = α·o·regRoot′ + g;  ∂q_e/∂x = α·o′·regRoot
        let mut dq_dp = [[0.0; 4]; 4];
        let mut dq_dx = [0.0; 4];
        for e in &edges[..n] {
            let dp = p[e.from] - p[e.to];
            let g = self.alpha * e.opening * reg_root_derivative(dp, self.p_tr) + e.leak;
            let d = self.alpha * e.slope * reg_root(dp, self.p_tr);
            for (port, s) in [(e.from, 1.0), (e.to, -1.0)] {
                dq_dp[port][e.from] += s * g;
                dq_dp[port][e.to] -= s * g;
                dq_dx[port] += s * d;
            }
        }
        for port in 0..4 {
            let row = jac.row(Slot::Flow(port), 0);
            for (k, d) in dq_dp[port].iter().enumerate() {
                if *d != 0.0 {
                    jac.set(row, jac.effort_col(k, 0), *d);
                }
            }
            self.x_v.partials(io, 0, |i, d| {
                jac.set(row, jac.input_col(i, 0), dq_dx[port] * d)
            });
        }
        true
    }
}

/// A fraction of the stroke in [0, 1).
const LAP: Range = Range {
    hi_open: true,
    ..Range::FRACTION
};

/// Kind `hydraulics.directional_valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.directional_valve",
    "4/3 directional valve, ports P, T, A, B: four edges Q = α·o(x_v)·regRoot(Δp), centre closed/open/tandem/float, overlap/underlap",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::modulated("x_v", "1", "spool stroke, clamped to [−1, 1], e.g. \"spool.out\""),
        ParamDecl::choice("centre", &["closed", "open", "tandem", "float"], "closed", "connections of the middle position"),
        ParamDecl::number("centre_area", "1", "area of the centre passages, as a fraction of α").non_negative().default(1.0),
        ParamDecl::number("centre_stroke", "1", "stroke at which the centre passages are shut")
            .range(Range { lo_open: true, ..Range::FRACTION })
            .default(0.2),
        ParamDecl::number("overlap", "1", "dead band, fraction of the stroke").range(LAP).default(0.0),
        ParamDecl::number("underlap", "1", "underlap, fraction of the stroke").range(LAP).default(0.0),
        ParamDecl::number("g_leak", "m³/(s·Pa)", "leak conductance of each metering edge").non_negative().default(1e-13),
        orifice::P_TR,
    ],
    |p| {
        let word = p.word("centre")?;
        let centre = Centre::from_word(&word)
            .ok_or_else(|| BuildError::invalid("centre", format!("unknown centre \"{word}\"")))?;
        let v = DirectionalValve::new(orifice::alpha_of(p)?, p.modulated("x_v")?)?
            .with_lap(p.number("overlap")?, p.number("underlap")?)?
            .with_centre(centre, p.number("centre_area")?, p.number("centre_stroke")?)?
            .with_leakage(p.number("g_leak")?, p.number("p_tr")?)?;
        Ok(Box::new(v))
    },
)
.simplifications(&[Simplification::new(
    "no_edge_leak",
    "metering edges tight when closed: g_leak = 0",
    &[Change::Set("g_leak", "0")],
)])
.example("alpha = 6e-7, x_v = \"0.5*sin(t)\", centre = \"open\"");

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact zeros and copied flows are meant exactly
mod tests {
    use super::*;

    fn valve(centre: Centre, overlap: f64, underlap: f64) -> DirectionalValve {
        DirectionalValve::new(1e-6, Param::modulated(vec!["u".into()], |_, u| u[0]))
            .unwrap()
            .with_lap(overlap, underlap)
            .unwrap()
            .with_centre(centre, 0.5, 0.25)
            .unwrap()
            .with_leakage(1e-13, 1e5)
            .unwrap()
    }

    const CENTRES: [Centre; 4] = [Centre::Closed, Centre::Open, Centre::Tandem, Centre::Float];

    /// A small deterministic generator of states (no dependency needed for 10⁴ points).
    fn states(n: usize) -> impl Iterator<Item = (f64, [f64; 4])> {
        let mut s: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n).map(move |_| {
            let x = 2.4 * next() - 1.2;
            let p = [0.0; 4].map(|_| 30e6 * next() - 1e6);
            (x, p)
        })
    }

    #[test]
    fn closed_centre_at_zero_passes_only_the_leaks() {
        let v = valve(Centre::Closed, 0.0, 0.0);
        let p = [20e6, 0.0, 12e6, 3e6];
        let q = v.flows(0.0, &p);
        // P leaks to A and B, A and B leak to T
        let g = 1e-13;
        let e = [
            g * (20e6 - 12e6) + g * (20e6 - 3e6),
            -g * (12e6 + 3e6),
            -g * (20e6 - 12e6) + g * 12e6,
            -g * (20e6 - 3e6) + g * 3e6,
        ];
        for k in 0..4 {
            assert!(
                (q[k] - e[k]).abs() <= 1e-12 * e[k].abs(),
                "{k}: {q:?} {e:?}"
            );
        }
        // an overlapped spool passes only the leaks over its whole dead band
        let v = valve(Centre::Closed, 0.1, 0.0);
        for x in [-0.1, -0.05, 0.03, 0.1] {
            assert_eq!(v.flows(x, &p), q, "{x}");
        }
    }

    #[test]
    fn metering_edges_are_orifices() {
        let v = valve(Centre::Closed, 0.0, 0.0)
            .with_leakage(0.0, 0.0)
            .unwrap();
        let p = [20e6, 1e6, 11e6, 5e6];
        let q = v.flows(0.6, &p);
        let (qa, qb) = (1e-6 * 0.6 * 9e6_f64.sqrt(), 1e-6 * 0.6 * 4e6_f64.sqrt());
        let e = [qa, -qb, -qa, qb];
        for k in 0..4 {
            assert!((q[k] - e[k]).abs() <= 1e-14 * e[k].abs(), "{q:?} {e:?}");
        }
        // the same as the crane's valve (eqs. 29–30) with supply and tank at P and T
        let crane = crate::Valve::new(1e-6, 0.0, 20e6, 1e6, 0.0).unwrap();
        for x in [-0.8, 0.3] {
            let (q_a, q_b) = crane.flows(x, 11e6, 5e6);
            let q = v.flows(x, &p);
            assert!(
                (q[A] + q_a).abs() <= 1e-14 * q_a.abs() && (q[B] + q_b).abs() <= 1e-14 * q_b.abs()
            );
        }
        // overlap: the edge opens at |x| = overlap and is fully open at |x| = 1
        let v = valve(Centre::Closed, 0.2, 0.0)
            .with_leakage(0.0, 0.0)
            .unwrap();
        let q = v.flows(0.6, &p);
        assert!((q[P] - 1e-6 * 0.5 * 9e6_f64.sqrt()).abs() < 1e-15);
        assert!((v.flows(1.0, &p)[P] - 1e-6 * 9e6_f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn underlap_bridges_p_to_t_at_centre() {
        // all four edges open by u/(1 + u) at x = 0: with A and B between P and T, the bridge
        let v = valve(Centre::Closed, 0.0, 0.1)
            .with_leakage(0.0, 0.0)
            .unwrap();
        let o = 0.1 / 1.1;
        let p = [20e6, 0.0, 10e6, 10e6];
        let q = v.flows(0.0, &p);
        let e = 2.0 * 1e-6 * o * reg_root(10e6, 0.0);
        assert!(
            (q[P] - e).abs() <= 1e-12 * e && (q[T] + e).abs() <= 1e-12 * e,
            "{q:?}"
        );
        assert!(q[A].abs() < 1e-18 && q[B].abs() < 1e-18);
    }

    #[test]
    fn centre_types_connect_what_they_say() {
        let p = [20e6, 0.0, 12e6, 3e6];
        let flow_at = |c: Centre| {
            valve(c, 0.0, 0.0)
                .with_leakage(0.0, 0.0)
                .unwrap()
                .flows(0.0, &p)
        };
        let c = |dp: f64| 1e-6 * 0.5 * reg_root(dp, 0.0);
        assert_eq!(flow_at(Centre::Closed), [0.0; 4]);
        let t = flow_at(Centre::Tandem);
        assert!((t[P] - c(20e6)).abs() < 1e-18 && t[A] == 0.0 && t[B] == 0.0);
        let f = flow_at(Centre::Float);
        assert!(f[P] == 0.0 && (f[A] - c(12e6)).abs() < 1e-18 && (f[B] - c(3e6)).abs() < 1e-18);
        let o = flow_at(Centre::Open);
        assert!((o[P] - c(20e6)).abs() < 1e-18 && (o[A] - c(12e6)).abs() < 1e-18);
        // the passages are shut beyond the centre stroke
        for centre in CENTRES {
            let v = valve(centre, 0.0, 0.0).with_leakage(0.0, 0.0).unwrap();
            let closed = valve(Centre::Closed, 0.0, 0.0)
                .with_leakage(0.0, 0.0)
                .unwrap();
            assert_eq!(v.flows(0.3, &p), closed.flows(0.3, &p));
        }
    }

    #[test]
    fn conserves_volume_dissipates_and_is_symmetric_at_random_states() {
        for centre in CENTRES {
            for (overlap, underlap) in [(0.0, 0.0), (0.1, 0.0), (0.0, 0.05)] {
                let v = valve(centre, overlap, underlap);
                for (x, p) in states(2000) {
                    let q = v.flows(x, &p);
                    let through = q.iter().map(|v| v.abs()).sum::<f64>();
                    let sum: f64 = q.iter().sum();
                    assert!(
                        sum.abs() <= 1e-14 * through,
                        "{centre:?} {x} {p:?}: {sum:e}"
                    );
                    let power: f64 = (0..4).map(|k| p[k] * q[k]).sum();
                    let scale: f64 = (0..4).map(|k| (p[k] * q[k]).abs()).sum();
                    assert!(power >= -1e-12 * scale, "{centre:?} {x} {p:?}: {power:e}");
                    // A ↔ B with the spool reversed: the same flows, A's and B's swapped
                    let m = v.flows(-x, &[p[P], p[T], p[B], p[A]]);
                    let e = [q[P], q[T], q[B], q[A]];
                    for k in 0..4 {
                        assert!((m[k] - e[k]).abs() <= 1e-14 * through, "{centre:?} {x}");
                    }
                }
            }
        }
    }

    #[test]
    fn partials_match_central_differences() {
        use bondgraph::check_partials;
        let ports = [(1, 1.0, PortCausality::FlowOut); 4];
        for centre in CENTRES {
            for (overlap, underlap) in [(0.0, 0.0), (0.1, 0.0), (0.0, 0.05)] {
                let v = valve(centre, overlap, underlap);
                for x in [-0.7, -0.12, 0.04, 0.2, 0.5] {
                    for p in [[20e6, 1e5, 12e6, 3e6], [8e6, 2e5, 12e6, 8.05e6]] {
                        let point = [p[0], 1e-4, p[1], 1e-4, p[2], 1e-4, p[3], 1e-4, x];
                        assert_eq!(
                            check_partials(&v, &ports, &point),
                            Ok(1),
                            "{centre:?} {overlap} {underlap} {x} {p:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(DirectionalValve::new(0.0, 0.0).is_err());
        assert!(DirectionalValve::new(1e-6, f64::NAN).is_err());
        let v = || DirectionalValve::new(1e-6, 0.0).unwrap();
        assert!(v().with_lap(0.1, 0.1).is_err());
        assert!(v().with_lap(1.0, 0.0).is_err());
        assert!(v().with_lap(-0.1, 0.0).is_err());
        assert!(v().with_centre(Centre::Open, 1.0, 0.0).is_err());
        assert!(v().with_centre(Centre::Open, -1.0, 0.2).is_err());
        assert!(v().with_leakage(-1.0, 1e5).is_err());
        assert_eq!(Centre::from_word("tandem"), Some(Centre::Tandem));
        assert_eq!(Centre::from_word("tanden"), None);
    }
}
