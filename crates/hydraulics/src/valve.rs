//! Directional control valve `hydraulics.valve` (4/3, proportional, closed centre): the two
//! modulated flow sources of the paper's eqs. 29–30, one per cylinder line.
//!
//! With spool stroke x_v ∈ [−1, 1] (clamped), supply pressure P_s, tank pressure P_T and the
//! line pressures P_A (piston side), P_B (rod side), the flows *delivered into* the lines are
//!
//! ```text
//! x_v ≥ 0:  Q_A =  α·x_v·regRoot(P_s − P_A)    Q_B = −α·x_v·regRoot(P_B − P_T)
//! x_v < 0:  Q_A =  α·x_v·regRoot(P_A − P_T)    Q_B = −α·x_v·regRoot(P_s − P_B)
//! ```
//!
//! (x_v ≥ 0 connects A to supply and B to tank; x_v < 0 the reverse.) With `p_tr = 0`,
//! `regRoot` is `sign·√|·|` and these are eqs. 29–30 verbatim; see [`crate::orifice`]. Both
//! branches give zero flow at x_v = 0, so the law is continuous in x_v.
//!
//! Causality: ports `A` and `B` receive the line pressures and set the flows (the paper's
//! modulated `Sf`s, which read the chamber pressures). Draw the bonds from the valve to the
//! lines: the bond flow is then Q_A (Q_B).

use crate::orifice;
use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage,
};

use crate::orifice::{reg_root, reg_root_derivative};

/// 4/3 proportional directional valve.
///
/// * `alpha` — orifice coefficient α at full opening, m³/(s·√Pa), > 0 (eq. 31).
/// * `x_v` — spool stroke, dimensionless, may be modulated; clamped to [−1, 1].
/// * `p_s`, `p_t` — supply and tank pressure, Pa (gauge), `p_s > p_t`.
/// * `p_tr` — transition pressure of the square-root regularisation, Pa, ≥ 0.
#[derive(Debug)]
pub struct Valve {
    alpha: f64,
    x_v: Param,
    p_s: f64,
    p_t: f64,
    p_tr: f64,
}

impl Valve {
    /// A valve; see the struct documentation for the parameters.
    pub fn new(
        alpha: f64,
        x_v: impl Into<Param>,
        p_s: f64,
        p_t: f64,
        p_tr: f64,
    ) -> Result<Self, ParamError> {
        ParamError::positive("alpha", alpha)?;
        ParamError::finite("p_s", p_s)?;
        ParamError::finite("p_t", p_t)?;
        ParamError::non_negative("p_tr", p_tr)?;
        if p_s <= p_t {
            return Err(ParamError::Shape {
                param: "p_s".into(),
                message: format!("supply pressure {p_s} Pa must exceed tank pressure {p_t} Pa"),
            });
        }
        let x_v = x_v.into();
        if let Some(x) = x_v.constant() {
            ParamError::finite("x_v", x)?;
        }
        Ok(Self {
            alpha,
            x_v,
            p_s,
            p_t,
            p_tr,
        })
    }

    /// Flows `(Q_A, Q_B)` delivered into lines A and B at spool stroke `x_v` (clamped to
    /// [−1, 1]) and line pressures `p_a`, `p_b`.
    #[must_use]
    pub fn flows(&self, x_v: f64, p_a: f64, p_b: f64) -> (f64, f64) {
        (self.line_flow(0, x_v, p_a), self.line_flow(1, x_v, p_b))
    }

    /// The flow delivered into line `line` (0: A, 1: B) at line pressure `p`: one of
    /// [`flows`](Self::flows)' pair, computed alone.
    #[must_use]
    pub fn line_flow(&self, line: usize, x_v: f64, p: f64) -> f64 {
        let x = x_v.clamp(-1.0, 1.0);
        let r = |dp: f64| self.alpha * x * reg_root(dp, self.p_tr);
        match (line, x >= 0.0) {
            (0, true) => r(self.p_s - p),
            (0, false) => r(p - self.p_t),
            (_, true) => -r(p - self.p_t),
            (_, false) => -r(self.p_s - p),
        }
    }

    /// The partials of the flow into line `line` (0: A, 1: B) with respect to its pressure
    /// and to the spool stroke x_v: `(∂Q/∂P, ∂Q/∂x_v)`. The clamp has slope 0 outside
    /// [−1, 1]; at x_v = 0 the derivatives are those of the x_v ≥ 0 side, which `flows`
    /// evaluates there.
    #[must_use]
    pub fn flow_partials(&self, line: usize, x_v: f64, p: f64) -> (f64, f64) {
        let x = x_v.clamp(-1.0, 1.0);
        let dx = if (-1.0..=1.0).contains(&x_v) {
            1.0
        } else {
            0.0
        };
        let (rr, drr) = (
            |d: f64| reg_root(d, self.p_tr),
            |d: f64| reg_root_derivative(d, self.p_tr),
        );
        let a = self.alpha;
        match (line, x >= 0.0) {
            // Q_A = α·x·rr(P_s − P_A)
            (0, true) => (-a * x * drr(self.p_s - p), a * rr(self.p_s - p) * dx),
            // Q_A = α·x·rr(P_A − P_T)
            (0, false) => (a * x * drr(p - self.p_t), a * rr(p - self.p_t) * dx),
            // Q_B = −α·x·rr(P_B − P_T)
            (_, true) => (-a * x * drr(p - self.p_t), -a * rr(p - self.p_t) * dx),
            // Q_B = −α·x·rr(P_s − P_B)
            (_, false) => (a * x * drr(self.p_s - p), -a * rr(self.p_s - p) * dx),
        }
    }
}

impl Element for Valve {
    fn kind(&self) -> &str {
        "hydraulics.valve"
    }
    fn energy_role(&self, _: usize) -> bondgraph::EnergyRole {
        // Two modulated flow sources fed from the supply pressure P_s (eqs. 29–30): the
        // energy they deliver comes from outside the graph.
        bondgraph::EnergyRole::Source
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("A", 1), PortSpec::new("B", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![PortCausality::FlowOut, PortCausality::FlowOut])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.x_v.signal_inputs()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        // Line A's flow needs only line A's pressure (and the spool), likewise B.
        let spool: Vec<Slot> = (0..self.x_v.n_inputs()).map(Slot::Input).collect();
        (0..2)
            .map(|p| {
                let mut reads = vec![Slot::Effort(p)];
                reads.extend(spool.iter().copied());
                Stage {
                    writes: vec![Slot::Flow(p)],
                    reads,
                }
            })
            .collect()
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let x = self.x_v.value(io, 0);
        // stage 0 sets line A, stage 1 line B; delivered into the line: the flow into the
        // valve is its negative
        let line = stage.min(1);
        let q = self.line_flow(line, x, io.e(line, 0));
        io.set_f_in(line, 0, -q);
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let x = self.x_v.value(io, 0);
        let line = stage.min(1);
        let (dq_dp, dq_dx) = self.flow_partials(line, x, io.e(line, 0));
        // f_in = −Q
        let row = jac.row(Slot::Flow(line), 0);
        jac.set(row, jac.effort_col(line, 0), -dq_dp);
        self.x_v
            .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), -dq_dx * d));
        true
    }
}

/// Kind `hydraulics.valve`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.valve",
    "4/3 directional valve, eqs. 29–30 with regRoot: ports A (piston side), B (rod side)",
    &[
        orifice::ALPHA,
        orifice::CD,
        orifice::W,
        orifice::RHO,
        ParamDecl::modulated(
            "x_v",
            "1",
            "spool stroke, clamped to [−1, 1], e.g. \"spool.out\"",
        ),
        ParamDecl::number("p_s", "Pa", "supply pressure"),
        ParamDecl::number("p_t", "Pa", "tank pressure").default(0.0),
        orifice::P_TR,
    ],
    |p| {
        Ok(Box::new(Valve::new(
            orifice::alpha_of(p)?,
            p.modulated("x_v")?,
            p.number("p_s")?,
            p.number("p_t")?,
            p.number("p_tr")?,
        )?))
    },
)
.example("alpha = 1e-7, x_v = \"0.5*sin(t)\", p_s = 2e7");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_flow_is_bit_identical_to_the_pair_formula() {
        // the pair as computed before the per-line split (both branches, p_tr = 0 and > 0)
        for p_tr in [0.0, 2e5] {
            let v = Valve::new(3e-7, 0.0, 2.1e7, 1e5, p_tr).unwrap();
            for x_v in [-1.4, -0.63, -1e-9, 0.0, 1e-9, 0.37, 1.0, 2.0] {
                for (p_a, p_b) in [(5e6, 1.2e7), (2.3e7, 4e4), (1e5, 1e5), (-3e5, 2.1e7)] {
                    let x = f64::clamp(x_v, -1.0, 1.0);
                    let r = |dp: f64| v.alpha * x * reg_root(dp, v.p_tr);
                    let pair = if x >= 0.0 {
                        (r(v.p_s - p_a), -r(p_b - v.p_t))
                    } else {
                        (r(p_a - v.p_t), -r(v.p_s - p_b))
                    };
                    let (q_a, q_b) = (v.line_flow(0, x_v, p_a), v.line_flow(1, x_v, p_b));
                    assert_eq!(q_a.to_bits(), pair.0.to_bits(), "x_v {x_v}, P_A {p_a}");
                    assert_eq!(q_b.to_bits(), pair.1.to_bits(), "x_v {x_v}, P_B {p_b}");
                }
            }
        }
    }

    /// Eqs. 29–30 written out as printed, with P_r the tank pressure.
    fn paper(alpha: f64, x: f64, p_s: f64, p_t: f64, pp: f64, pr: f64) -> (f64, f64) {
        let sq = |d: f64| d.signum() * d.abs().sqrt();
        if x >= 0.0 {
            (alpha * sq(p_s - pp) * x, -alpha * sq(pr - p_t) * x)
        } else {
            (alpha * sq(pp - p_t) * x, -alpha * sq(p_s - pr) * x)
        }
    }

    #[test]
    fn zero_transition_pressure_reproduces_eqs_29_30() {
        let a = crate::orifice::alpha(0.6, 0.0007, 880.0).unwrap();
        let v = Valve::new(a, 0.0, 25e6, 0.0, 0.0).unwrap();
        for x in [-1.0, -0.3, 0.0, 0.2, 1.0] {
            for (pa, pb) in [(11e6, 1e6), (26e6, -0.5e6), (0.0, 25e6), (3e5, 3e5)] {
                let (qa, qb) = v.flows(x, pa, pb);
                let (ea, eb) = paper(a, x, 25e6, 0.0, pa, pb);
                assert!(
                    (qa - ea).abs() <= 1e-14 * ea.abs().max(1e-9),
                    "{x} {pa}: {qa} {ea}"
                );
                assert!(
                    (qb - eb).abs() <= 1e-14 * eb.abs().max(1e-9),
                    "{x} {pb}: {qb} {eb}"
                );
            }
        }
    }

    #[test]
    fn regularised_law_is_within_2p5e_5_of_eqs_29_30_far_from_zero() {
        let a = 1e-6;
        let v = Valve::new(a, 0.0, 25e6, 0.0, 1e5).unwrap();
        for x in [-1.0, -0.5, 0.5, 1.0] {
            // every orifice pressure drop is ≥ 1e7 = 100·p_tr here
            let (qa, qb) = v.flows(x, 12e6, 12e6 - 2e6 * x.signum());
            let (ea, eb) = paper(a, x, 25e6, 0.0, 12e6, 12e6 - 2e6 * x.signum());
            assert!((qa - ea).abs() <= 2.5e-5 * ea.abs(), "{qa} {ea}");
            assert!((qb - eb).abs() <= 2.5e-5 * eb.abs(), "{qb} {eb}");
        }
    }

    #[test]
    fn flows_are_c1_in_the_line_pressure_at_zero_drop() {
        // x_v > 0: line B drains to tank; at P_B = P_T the slope is α·x/√p_tr from both sides.
        let (a, x, p_tr): (f64, f64, f64) = (1e-6, 0.4, 1e5);
        let v = Valve::new(a, 0.0, 25e6, 0.0, p_tr).unwrap();
        let slope = -a * x / p_tr.sqrt();
        let qb = |p: f64| v.flows(x, 10e6, p).1;
        for h in [1.0, 10.0] {
            let right = (qb(h) - qb(0.0)) / h;
            let left = (qb(0.0) - qb(-h)) / h;
            assert!(
                (right - slope).abs() <= 1e-6 * slope.abs(),
                "{right:e} vs {slope:e}"
            );
            assert!(
                (left - slope).abs() <= 1e-6 * slope.abs(),
                "{left:e} vs {slope:e}"
            );
        }
    }

    #[test]
    fn partials_match_central_differences_on_both_sides_and_clamped() {
        use bondgraph::check_partials;
        let x_v = Param::modulated(vec!["spool".into()], |_, u| 2.0 * u[0]);
        let v = Valve::new(1e-6, x_v, 25e6, 0.0, 1e5).unwrap();
        let ports = [
            (1, -1.0, PortCausality::FlowOut),
            (1, -1.0, PortCausality::FlowOut),
        ];
        for spool in [0.2, -0.3, 0.8, -0.9] {
            for (pa, pb) in [(11e6, 1e6), (3e4, 24.99e6), (25.02e6, -2e4)] {
                // P_A, Q_A, P_B, Q_B, spool
                let point = [pa, 1e-3, pb, 1e-3, spool];
                assert_eq!(
                    check_partials(&v, &ports, &point),
                    Ok(2),
                    "{spool} {pa} {pb}"
                );
            }
        }
    }

    #[test]
    fn spool_is_clamped_and_parameters_checked() {
        let v = Valve::new(1e-6, 0.0, 25e6, 0.0, 1e5).unwrap();
        assert_eq!(v.flows(3.0, 1e6, 1e6), v.flows(1.0, 1e6, 1e6));
        assert!(Valve::new(1e-6, 0.0, 1e6, 2e6, 1e5).is_err());
        assert!(Valve::new(-1e-6, 0.0, 25e6, 0.0, 1e5).is_err());
        assert!(Valve::new(1e-6, 0.0, 25e6, 0.0, -1.0).is_err());
        assert!(Valve::new(1e-6, f64::INFINITY, 25e6, 0.0, 1e5).is_err());
    }
}
