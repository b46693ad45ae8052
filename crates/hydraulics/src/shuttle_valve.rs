//! Shuttle valve `hydraulics.shuttle_valve`: the higher of two pressures passes to the
//! outlet (the OR element of a load-sensing network).
//!
//! A ball between two seats is pushed off the seat of the higher inlet onto the other's; the
//! open side passes oil to `out` as an orifice. The ball's travel is smooth over a switching
//! band Δp_sw:
//!
//! ```text
//! σ = S((P_a − P_b)/Δp_sw),   S(u) = ramp(u + ½, ½)   (0 for u ≤ −1, 1 for u ≥ 1, C¹, S(u) + S(−u) = 1)
//! Q_a = α·σ·regRoot(P_a − P_out)            a → out
//! Q_b = α·(1 − σ)·regRoot(P_b − P_out)      b → out
//! ```
//!
//! so with no flow drawn at `out` its pressure is a smooth maximum of the two: exactly
//! max(P_a, P_b) once they differ by more than Δp_sw, a weighted mean inside the band (the
//! root of σ·regRoot(P_a − P_out) + (1 − σ)·regRoot(P_b − P_out) = 0); the bleed of an LS
//! line drawn through the open side lowers it by (Q/α)². Every opening passes oil along its
//! drop, so `Q_a·(P_a − P_out) + Q_b·(P_b − P_out) ≥ 0` and volume is conserved exactly.
//!
//! [`smooth_max`] is the closed-form smooth maximum the post-compensated section uses.
//!
//! Causality: conductance at the three ports (attach each to a 0-junction with a volume).

use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, Slot, Stage,
};

use crate::orifice::{self, reg_root, reg_root_derivative};
use crate::ramp::ramp;

/// The smooth maximum `(u + v + √((u − v)² + δ²))/2` and its partials (∂/∂u, ∂/∂v): C^∞ for
/// δ > 0, ≥ max(u, v), within δ²/(4|u − v|) of it away from u = v and δ/2 above it at u = v.
#[must_use]
pub fn smooth_max(u: f64, v: f64, delta: f64) -> (f64, f64, f64) {
    let d = u - v;
    let r = (d * d + delta * delta).sqrt();
    if r == 0.0 {
        return (u, 0.5, 0.5);
    }
    (0.5 * (u + v + r), 0.5 * (1.0 + d / r), 0.5 * (1.0 - d / r))
}

/// The ball's position σ ∈ [0, 1] (1: `a` open) and dσ/d(P_a − P_b).
fn ball(dp: f64, dp_switch: f64) -> (f64, f64) {
    let (s, ds) = ramp(0.5 + dp / dp_switch, 0.5);
    (s, ds / dp_switch)
}

/// A shuttle valve: inlets `a`, `b`, outlet `out`.
///
/// * `alpha` — orifice coefficient of each open seat, m³/(s·√Pa), > 0.
/// * `dp_switch` — switching band Δp_sw, Pa, > 0.
/// * `p_tr` — regRoot transition pressure, Pa, ≥ 0.
#[derive(Debug)]
pub struct ShuttleValve {
    alpha: f64,
    dp_switch: f64,
    p_tr: f64,
}

impl ShuttleValve {
    /// A shuttle valve; see the struct documentation.
    pub fn new(alpha: f64, dp_switch: f64, p_tr: f64) -> Result<Self, ParamError> {
        Ok(Self {
            alpha: ParamError::positive("alpha", alpha)?,
            dp_switch: ParamError::positive("dp_switch", dp_switch)?,
            p_tr: ParamError::non_negative("p_tr", p_tr)?,
        })
    }

    /// The flows (a → out, b → out) at pressures P_a, P_b, P_out.
    #[must_use]
    pub fn flows(&self, p_a: f64, p_b: f64, p_out: f64) -> (f64, f64) {
        let (s, _) = ball(p_a - p_b, self.dp_switch);
        (
            self.alpha * s * reg_root(p_a - p_out, self.p_tr),
            self.alpha * (1.0 - s) * reg_root(p_b - p_out, self.p_tr),
        )
    }
}

impl Element for ShuttleValve {
    fn kind(&self) -> &str {
        "hydraulics.shuttle_valve"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(["a", "b", "out"].map(|n| PortSpec::new(n, 1)).to_vec())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::FlowOut; 3]])
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        vec![Stage {
            writes: (0..3).map(Slot::Flow).collect(),
            reads: (0..3).map(Slot::Effort).collect(),
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let (qa, qb) = self.flows(io.e(0, 0), io.e(1, 0), io.e(2, 0));
        io.set_f_in(0, 0, qa);
        io.set_f_in(1, 0, qb);
        io.set_f_in(2, 0, -qa - qb);
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let (pa, pb, po) = (io.e(0, 0), io.e(1, 0), io.e(2, 0));
        let (s, ds) = ball(pa - pb, self.dp_switch);
        let (ra, rb) = (reg_root(pa - po, self.p_tr), reg_root(pb - po, self.p_tr));
        let (ga, gb) = (
            self.alpha * s * reg_root_derivative(pa - po, self.p_tr),
            self.alpha * (1.0 - s) * reg_root_derivative(pb - po, self.p_tr),
        );
        let (ka, kb) = (self.alpha * ds * ra, self.alpha * ds * rb);
        // ∂Q_a, ∂Q_b over (P_a, P_b, P_out)
        let qa = [ka + ga, -ka, -ga];
        let qb = [-kb, kb + gb, -gb];
        for (port, d) in [
            (0, qa),
            (1, qb),
            (2, [-qa[0] - qb[0], -qa[1] - qb[1], -qa[2] - qb[2]]),
        ] {
            let row = jac.row(Slot::Flow(port), 0);
            for (k, v) in d.iter().enumerate() {
                jac.set(row, jac.effort_col(k, 0), *v);
            }
        }
        true
    }
}

/// Kind `hydraulics.shuttle_valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.shuttle_valve",
    "shuttle valve a, b → out: the higher inlet passes, Q = α·σ·regRoot(Δp), the ball σ smooth over dp_switch",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::number("dp_switch", "Pa", "switching band: the ball crosses over as P_a − P_b goes from −dp_switch to dp_switch")
            .positive()
            .default(5e4),
        orifice::P_TR,
    ],
    |p| {
        Ok(Box::new(ShuttleValve::new(
            orifice::alpha_of(p)?,
            p.number("dp_switch")?,
            p.number("p_tr")?,
        )?))
    },
)
.example("alpha = 5e-7");

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact zeros and ones of the clamped ramps are meant exactly
mod tests {
    use super::*;
    use bondgraph::check_partials;

    fn valve() -> ShuttleValve {
        ShuttleValve::new(5e-7, 5e4, 1e5).unwrap()
    }

    /// The outlet pressure with no flow drawn, by bisection on the flow balance.
    fn dead_end(v: &ShuttleValve, pa: f64, pb: f64) -> f64 {
        let (mut lo, mut hi) = (pa.min(pb) - 1.0, pa.max(pb) + 1.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            let (qa, qb) = v.flows(pa, pb, mid);
            if qa + qb > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn the_higher_pressure_passes() {
        let v = valve();
        // beyond the switching band, the outlet is the maximum exactly
        for (pa, pb) in [(150e5, 40e5), (40e5, 150e5), (20e5, 19.4e5)] {
            let p = dead_end(&v, pa, pb);
            assert!((p - pa.max(pb)).abs() < 1e-6, "{pa} {pb}: {p}");
        }
        // equal inlets: that pressure; inside the band, a mean of the two that moves with
        // them without jumps
        assert!((dead_end(&v, 80e5, 80e5) - 80e5).abs() < 1e-6);
        let mut last = dead_end(&v, 80e5 - 6e4, 80e5);
        assert!((last - 80e5).abs() < 1e-6);
        for k in 1..=120 {
            let pa = 80e5 - 6e4 + 1e3 * f64::from(k);
            let p = dead_end(&v, pa, 80e5);
            assert!(
                p >= pa.min(80e5) - 1e-6 && p <= pa.max(80e5) + 1e-6,
                "{pa}: {p}"
            );
            assert!((p - last).abs() <= 2e3, "{pa}: {p} after {last}");
            last = p;
        }
        assert!((last - 80.6e5).abs() < 1e-6);
        // the ball: S(u) + S(−u) = 1, shut at u = ±1
        for u in [-1.3, -0.7, -0.2, 0.0, 0.4, 0.9] {
            let (s1, s2) = (ball(u * 5e4, 5e4).0, ball(-u * 5e4, 5e4).0);
            assert!((s1 + s2 - 1.0).abs() < 1e-15);
        }
        assert_eq!(ball(-5e4, 5e4).0, 0.0);
        assert_eq!(ball(5e4, 5e4).0, 1.0);
        // a bleed drawn at the outlet through the open side: drop (Q/α)² (regRoot above p_tr)
        let (qa, qb) = v.flows(150e5, 40e5, 150e5 - 4e6);
        assert!((qa - 5e-7 * reg_root(4e6, 1e5)).abs() < 1e-18 && qb == 0.0);
    }

    #[test]
    fn conserves_volume_and_dissipates() {
        let v = valve();
        for pa in [0.0, 19.8e5, 20e5, 150e5] {
            for pb in [0.0, 20.1e5, 90e5] {
                for po in [0.0, 20e5, 100e5, 200e5] {
                    let (qa, qb) = v.flows(pa, pb, po);
                    assert!(qa * (pa - po) >= 0.0 && qb * (pb - po) >= 0.0);
                }
            }
        }
    }

    #[test]
    fn smooth_max_and_its_partials() {
        let d = 1e4;
        for (u, v) in [(5e6, 1e6), (1e6, 5e6), (2e6, 2e6), (2e6, 2.003e6)] {
            let (m, du, dv) = smooth_max(u, v, d);
            assert!(m >= u.max(v) && m <= u.max(v) + 0.5 * d + 1e-9);
            let h = 1.0;
            let fu = (smooth_max(u + h, v, d).0 - smooth_max(u - h, v, d).0) / (2.0 * h);
            let fv = (smooth_max(u, v + h, d).0 - smooth_max(u, v - h, d).0) / (2.0 * h);
            assert!((fu - du).abs() < 1e-6 && (fv - dv).abs() < 1e-6, "{u} {v}");
        }
        assert!((smooth_max(5e6, 1e6, d).0 - 5e6).abs() < d * d / (4.0 * 4e6) + 1e-6);
    }

    #[test]
    fn partials_match_central_differences() {
        let ports = [(1, 1.0, PortCausality::FlowOut); 3];
        for (pa, pb, po) in [
            (150e5, 40e5, 149e5),
            (80e5, 80.02e5, 79.9e5),
            (80e5, 79.97e5, 80.5e5),
            (10e5, 90e5, 0.0),
        ] {
            let point = [pa, 1e-5, pb, 1e-5, po, -2e-5];
            assert_eq!(check_partials(&valve(), &ports, &point), Ok(1), "{pa} {pb}");
        }
    }
}
