//! Gas accumulator `hydraulics.accumulator`: a gas-charged (bladder or piston) accumulator
//! as a 1-port `C` whose state is the **oil volume** V in it (m³).
//!
//! The gas, precharged to p₀ at volume V₀ (the whole accumulator, no oil), is compressed
//! polytropically by the oil (Merritt, *Hydraulic Control Systems*, 1967, the gas-charged
//! accumulator; Jelali & Kroll, *Hydraulic Servo-systems*, 2003). With absolute pressures
//! (p_abs = p + p_atm, p gauge):
//!
//! ```text
//! V ≥ 0:   (p + p_atm)·(V₀ − V)ⁿ = (p₀ + p_atm)·V₀ⁿ
//!          p(V) = (p₀ + p_atm)·(V₀/(V₀ − V))ⁿ − p_atm
//! V < 0:   p(V) = p₀ + k_e·V + (k_g − k_e)·w·(e^(V/w) − 1),   k_g = n·(p₀ + p_atm)/V₀,
//!          k_e = β/V_dead,  w = V_dead
//! dV/dt = f_in
//! ```
//!
//! n = 1 is isothermal (slow cycles), n = 1.4 adiabatic (fast ones). **Below the precharge**
//! the bladder lies on its poppet and the accumulator is empty: what is left is the oil in
//! its neck and port, V_dead, as stiff as oil (k_e = β/V_dead). The two laws join C¹ at V = 0
//! (value p₀ and slope k_g), the slope turning from the gas's to the oil's over one dead
//! volume; V < 0 is the oil volume missing from the neck (decompressed oil). **Near full**
//! (gas volume below 1e-3·V₀) the law continues linearly with its slope there, so the
//! pressure stays finite whatever the inflow (the real accumulator is long past its rating).
//!
//! The oil volume as state keeps the Jacobian simple: ∂p/∂V is the stiffness above, and
//! dV/dt = f_in is linear. Volume is conserved by construction (V = ∫f_in dt), and the
//! element is conservative: the energy stored, E(V) = ∫₀^V p dV (gauge pressure: the work
//! done through the port), is [`stored_energy`](bondgraph::Element::stored_energy), with
//! the polytropic closed form
//!
//! ```text
//! n ≠ 1:  E(V) = (p₀ + p_atm)·V₀ⁿ·((V₀ − V)^(1−n) − V₀^(1−n))/(n − 1) − p_atm·V
//! n = 1:  E(V) = (p₀ + p_atm)·V₀·ln(V₀/(V₀ − V)) − p_atm·V
//! ```
//!
//! Causality: integral (the accumulator sets its pressure); derivative causality is refused.

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params, Range};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, Slot,
    Stage, StateSpec,
};

/// Smallest gas volume the polytropic law is used down to, as a fraction of V₀.
const GAS_FLOOR: f64 = 1e-3;

/// A gas accumulator with an oil-volume state.
///
/// * `p0` — precharge pressure p₀, Pa gauge, with p₀ + p_atm > 0;
/// * `v0` — gas volume at precharge V₀ (the accumulator's size), m³, > 0;
/// * `n` — polytropic exponent, in [1, 1.4] is usual (≥ 1 accepted, ≤ 2);
/// * `p_atm` — atmospheric pressure, Pa absolute (default 101 325);
/// * `beta` — oil bulk modulus for the empty accumulator, Pa (default 1.5e9);
/// * `v_dead` — oil volume left in neck and port when empty, m³ (default 1e-3·V₀);
/// * initial oil volume (default 0: empty at precharge), or an initial pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct Accumulator {
    p0_abs: f64,
    p_atm: f64,
    v0: f64,
    n: f64,
    /// k_e = β/V_dead.
    k_e: f64,
    /// w = V_dead.
    w: f64,
    v_oil0: f64,
}

impl Accumulator {
    /// An accumulator precharged to `p0` (Pa gauge) with gas volume `v0` (m³) and polytropic
    /// exponent `n`, empty at the start; the other parameters at their defaults.
    pub fn new(p0: f64, v0: f64, n: f64) -> Result<Self, ParamError> {
        ParamError::positive("v0", v0)?;
        ParamError::finite("p0", p0)?;
        if !(n.is_finite() && (1.0..=2.0).contains(&n)) {
            return Err(ParamError::OutOfRange {
                param: "n".into(),
                value: n,
                requirement: "in [1, 2] (1 isothermal, 1.4 adiabatic)",
            });
        }
        let p_atm = 101_325.0;
        Self::check_precharge(p0, p_atm)?;
        let v_dead = 1e-3 * v0;
        Ok(Self {
            p0_abs: p0 + p_atm,
            p_atm,
            v0,
            n,
            k_e: 1.5e9 / v_dead,
            w: v_dead,
            v_oil0: 0.0,
        })
    }

    fn check_precharge(p0: f64, p_atm: f64) -> Result<(), ParamError> {
        if p0 + p_atm > 0.0 {
            Ok(())
        } else {
            Err(ParamError::OutOfRange {
                param: "p0".into(),
                value: p0,
                requirement: "above absolute zero: p0 + p_atm > 0",
            })
        }
    }

    /// Set the atmospheric pressure, Pa absolute (> 0); the precharge p₀ stays gauge.
    pub fn with_atmosphere(mut self, p_atm: f64) -> Result<Self, ParamError> {
        ParamError::positive("p_atm", p_atm)?;
        let p0 = self.p0_abs - self.p_atm;
        Self::check_precharge(p0, p_atm)?;
        self.p0_abs = p0 + p_atm;
        self.p_atm = p_atm;
        Ok(self)
    }

    /// Set the empty accumulator's oil: bulk modulus `beta` (Pa, > 0) and dead volume
    /// `v_dead` (m³, > 0).
    pub fn with_empty_oil(mut self, beta: f64, v_dead: f64) -> Result<Self, ParamError> {
        ParamError::positive("beta", beta)?;
        ParamError::positive("v_dead", v_dead)?;
        self.k_e = beta / v_dead;
        self.w = v_dead;
        Ok(self)
    }

    /// Start with oil volume `v_oil` (m³, below V₀·(1 − 1e-3)).
    pub fn with_oil_volume(mut self, v_oil: f64) -> Result<Self, ParamError> {
        if !(v_oil.is_finite() && v_oil < self.v_max()) {
            return Err(ParamError::OutOfRange {
                param: "v_oil0".into(),
                value: v_oil,
                requirement: "finite and below the gas volume at precharge v0 (less 0.1 %)",
            });
        }
        self.v_oil0 = v_oil;
        Ok(self)
    }

    /// Start at gauge pressure `p` (Pa): the oil volume that gives it.
    pub fn with_pressure(self, p: f64) -> Result<Self, ParamError> {
        ParamError::finite("p_init", p)?;
        let v = self.volume_at(p);
        self.with_oil_volume(v)
    }

    /// The gas slope at V = 0, k_g = n·p₀,abs/V₀ (Pa/m³).
    fn k_g(&self) -> f64 {
        self.n * self.p0_abs / self.v0
    }

    /// Largest oil volume of the polytropic law.
    fn v_max(&self) -> f64 {
        self.v0 * (1.0 - GAS_FLOOR)
    }

    /// Gauge pressure p(V) (Pa) and stiffness dp/dV (Pa/m³) at oil volume `v`.
    #[must_use]
    pub fn pressure(&self, v: f64) -> (f64, f64) {
        if v < 0.0 {
            let (kg, ke, w) = (self.k_g(), self.k_e, self.w);
            let em1 = (v / w).exp_m1();
            let p = self.p0_abs - self.p_atm + ke * v + (kg - ke) * w * em1;
            return (p, kg + (kg - ke) * em1);
        }
        let vm = self.v_max();
        let gas = |v: f64| {
            let ratio = (self.v0 / (self.v0 - v)).powf(self.n);
            let p_abs = self.p0_abs * ratio;
            (p_abs - self.p_atm, self.n * p_abs / (self.v0 - v))
        };
        if v <= vm {
            gas(v)
        } else {
            let (p, k) = gas(vm);
            (p + k * (v - vm), k)
        }
    }

    /// The oil volume at gauge pressure `p` (the inverse of [`pressure`](Self::pressure)):
    /// closed form on the gas branch, Newton's method (monotone) below the precharge.
    #[must_use]
    pub fn volume_at(&self, p: f64) -> f64 {
        let p_abs = p + self.p_atm;
        if p_abs >= self.p0_abs {
            let (pm, km) = self.pressure(self.v_max());
            if p > pm {
                return self.v_max() + (p - pm) / km;
            }
            return self.v0 * (1.0 - (self.p0_abs / p_abs).powf(1.0 / self.n));
        }
        // p(V) is increasing and concave for V < 0; Newton from V = 0 converges monotonically
        let mut v = 0.0;
        for _ in 0..200 {
            let (pv, k) = self.pressure(v);
            let step = (pv - p) / k;
            v -= step;
            if step.abs() <= 1e-15 * (v.abs() + self.w) {
                break;
            }
        }
        v
    }

    /// Energy stored E(V) = ∫₀^V p dV (J), closed form.
    #[must_use]
    pub fn energy(&self, v: f64) -> f64 {
        let (pa, v0, n) = (self.p0_abs, self.v0, self.n);
        if v < 0.0 {
            let (kg, ke, w) = (self.k_g(), self.k_e, self.w);
            let p0 = pa - self.p_atm;
            return p0 * v + 0.5 * ke * v * v + (kg - ke) * w * (w * (v / w).exp_m1() - v);
        }
        let gas = |v: f64| {
            let e_abs = if (n - 1.0).abs() < 1e-12 {
                pa * v0 * (v0 / (v0 - v)).ln()
            } else {
                pa * v0.powf(n) * ((v0 - v).powf(1.0 - n) - v0.powf(1.0 - n)) / (n - 1.0)
            };
            e_abs - self.p_atm * v
        };
        let vm = self.v_max();
        if v <= vm {
            gas(v)
        } else {
            let (pm, km) = self.pressure(vm);
            let d = v - vm;
            gas(vm) + pm * d + 0.5 * km * d * d
        }
    }
}

impl Element for Accumulator {
    fn kind(&self) -> &str {
        "hydraulics.accumulator"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Integral(vec![PortCausality::EffortOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        vec![StateSpec::new("V", self.v_oil0).nominal(self.v0)]
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        Stage::from_states(causality, 0, 0)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let p = self.pressure(io.states()[0]).0;
        io.set_e(0, 0, p);
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        dx[0] = io.f_in(0, 0);
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let k = self.pressure(io.states()[0]).1;
        jac.set(jac.row(Slot::Effort(0), 0), jac.state_col(0), k);
        true
    }
    fn derivative_partials(&self, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        jac.set(jac.derivative_row(0), jac.flow_col(0, 0), 1.0);
        true
    }
    fn stored_energy(&self, x: &[f64]) -> Option<f64> {
        Some(self.energy(x[0]))
    }
}

/// Kind `hydraulics.accumulator`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.accumulator",
    "gas accumulator, C with oil-volume state: (p + p_atm)(V₀ − V)ⁿ = (p₀ + p_atm)V₀ⁿ, stiff oil below p₀",
    &[
        ParamDecl::number("p0", "Pa", "precharge pressure (gauge), p0 + p_atm > 0"),
        ParamDecl::number("v0", "m³", "gas volume at precharge (the accumulator's size)").positive(),
        ParamDecl::number("n", "1", "polytropic exponent (1 isothermal, 1.4 adiabatic)")
            .range(Range::closed(1.0, 2.0))
            .default(1.4),
        ParamDecl::number("p_atm", "Pa", "atmospheric pressure, absolute")
            .positive()
            .default(101_325.0),
        ParamDecl::number("beta", "Pa", "oil bulk modulus of the empty accumulator")
            .positive()
            .default(1.5e9),
        ParamDecl::number("v_dead", "m³", "oil left in neck and port when empty")
            .positive()
            .optional("1e-3 of v0"),
        ParamDecl::number("p_init", "Pa", "initial pressure (gauge)")
            .optional("p0: empty at precharge"),
        ParamDecl::number("v_oil0", "m³", "initial oil volume, below 0.999·v0, instead of p_init")
            .optional("0: empty at precharge"),
    ],
    build,
)
.example("p0 = 5e6, v0 = 4e-3, p_init = 8e6");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    let v0 = p.number("v0")?;
    let mut a = Accumulator::new(p.number("p0")?, v0, p.number("n")?)?
        .with_atmosphere(p.number("p_atm")?)?;
    if p.has("beta") || p.has("v_dead") {
        let v_dead = p.optional("v_dead")?.unwrap_or(1e-3 * v0);
        a = a.with_empty_oil(p.number("beta")?, v_dead)?;
    }
    let a = match (p.optional("p_init")?, p.optional("v_oil0")?) {
        (Some(_), Some(_)) => {
            return Err(BuildError::conflict(
                "v_oil0",
                "give either `p_init` or `v_oil0`, not both",
            ))
        }
        (Some(pi), None) => a.with_pressure(pi)?,
        (None, Some(v)) => a.with_oil_volume(v)?,
        (None, None) => a,
    };
    Ok(Box::new(a))
}

#[cfg(test)]
mod tests {
    use super::*;
    use bondgraph::{
        assign_causality, check_partials, simulate, BondGraph, FlowSource, Output, Settings,
        StateEquations,
    };

    const P_ATM: f64 = 101_325.0;

    /// Charge at a constant 0.5 l/s for 7 s (3.5 l into a 4 l accumulator precharged to
    /// 5 MPa): returns (t, V, p) rows.
    fn charging_run(acc: Accumulator, q: f64, t_end: f64) -> Vec<(f64, f64, f64)> {
        let mut g = BondGraph::new();
        g.add("acc", acc).unwrap();
        g.add("pump", FlowSource::new(q)).unwrap();
        g.connect_names("pump", "acc").unwrap();
        let mut eqs = StateEquations::new(assign_causality(g).unwrap()).unwrap();
        let outputs: Vec<Output> = ["acc.V", "acc.e"]
            .iter()
            .map(|p| Output {
                name: (*p).into(),
                probe: eqs.probe(p).unwrap(),
            })
            .collect();
        let settings = Settings {
            t_end,
            dt_out: t_end / 1000.0,
            rtol: 1e-10,
            atol: 1e-10,
            ..Settings::default()
        };
        let x0 = eqs.initial_state();
        let run = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
        assert!(run.error.is_none(), "{:?}", run.error);
        let tr = &run.trajectory;
        let (t, v, p) = (
            tr.column("t").unwrap(),
            tr.column("acc.V").unwrap(),
            tr.column("acc.e").unwrap(),
        );
        (0..t.len()).map(|k| (t[k], v[k], p[k])).collect()
    }

    #[test]
    fn charging_follows_the_polytropic_law_and_conserves_volume() {
        let (p0, v0, q) = (5e6, 4e-3, 5e-4);
        for n in [1.0, 1.4] {
            let rows = charging_run(Accumulator::new(p0, v0, n).unwrap(), q, 7.0);
            let invariant = (p0 + P_ATM) * v0.powf(n);
            let mut worst_law: f64 = 0.0;
            let mut worst_volume: f64 = 0.0;
            for &(t, v, p) in &rows {
                // volume: the state is ∫Q dt
                worst_volume = worst_volume.max((v - q * t).abs() / v0);
                // p·(V₀ − V)ⁿ = p₀·V₀ⁿ in absolute pressures
                worst_law = worst_law.max(((p + P_ATM) * (v0 - v).powf(n) / invariant - 1.0).abs());
            }
            let &(_, _, p_end) = rows.last().unwrap();
            eprintln!(
                "n = {n}: final p {p_end:.4e} Pa; law {worst_law:.1e}, volume {worst_volume:.1e}"
            );
            assert!(p_end > 3.0 * p0, "charged: {p_end}");
            assert!(worst_law < 1e-12, "polytropic law off by {worst_law:e}");
            assert!(worst_volume < 1e-9, "volume off by {worst_volume:e} of V₀");
        }
    }

    #[test]
    fn energy_stored_is_the_port_work_and_the_closed_form() {
        let (p0, v0, q) = (5e6, 4e-3, 5e-4);
        for n in [1.0, 1.2, 1.4] {
            let acc = Accumulator::new(p0, v0, n).unwrap();
            let rows = charging_run(acc.clone(), q, 7.0);
            // ∫p·Q dt by the trapezoidal rule over 1000 rows: its error is ~(Δt)²·ṗ·Q/12
            let mut work = 0.0;
            for w in rows.windows(2) {
                work += 0.5 * (w[0].2 + w[1].2) * q * (w[1].0 - w[0].0);
            }
            let &(_, v_end, _) = rows.last().unwrap();
            let closed = acc.energy(v_end);
            eprintln!("n = {n}: E = {closed:.6e} J, ∫p dV = {work:.6e} J");
            assert!((work / closed - 1.0).abs() < 1e-5, "{work} vs {closed}");
            assert_eq!(acc.stored_energy(&[v_end]), Some(closed));
        }
    }

    #[test]
    fn energy_is_the_integral_of_the_pressure_on_every_branch() {
        let acc = Accumulator::new(2e6, 1e-3, 1.3)
            .unwrap()
            .with_empty_oil(1.5e9, 1e-5)
            .unwrap();
        // Simpson's rule of p(V) from 0 to V, against energy(V): below, across and beyond
        for v_end in [-3e-5, -1e-6, 5e-4, 9.95e-4, 9.999e-4] {
            let m = 20_000;
            let h = v_end / f64::from(m);
            let mut s = acc.pressure(0.0).0 + acc.pressure(v_end).0;
            for i in 1..m {
                let w = if i % 2 == 1 { 4.0 } else { 2.0 };
                s += w * acc.pressure(f64::from(i) * h).0;
            }
            let simpson = s * h / 3.0;
            let e = acc.energy(v_end);
            assert!(
                (simpson - e).abs() <= 1e-7 * e.abs(),
                "{v_end}: {simpson} vs {e}"
            );
        }
    }

    #[test]
    fn empty_branch_joins_the_gas_law_smoothly_and_inverts() {
        let acc = Accumulator::new(1e6, 2e-3, 1.4).unwrap();
        let (p0, k0) = acc.pressure(0.0);
        let (pm, km) = acc.pressure(-1e-22);
        assert!((p0 - 1e6).abs() < 1e-6 && (pm - p0).abs() < 1e-3);
        assert!((km / k0 - 1.0).abs() < 1e-9, "C¹ at V = 0: {km} vs {k0}");
        // stiff as oil once the neck is drained: β/V_dead
        let (_, k_deep) = acc.pressure(-1e-4);
        assert!((k_deep / (1.5e9 / 2e-6) - 1.0).abs() < 1e-9);
        // finite and continuous past the gas floor
        let vm = 2e-3 * (1.0 - GAS_FLOOR);
        let (a, b) = (acc.pressure(vm).0, acc.pressure(vm * (1.0 + 1e-12)).0);
        assert!((a - b).abs() < 1e-6 * a);
        for p in [-5e5, 0.0, 1e6, 3e6, 2e7, 1e11] {
            let v = acc.volume_at(p);
            assert!(
                (acc.pressure(v).0 - p).abs() < 1e-6 * p.abs().max(1e5),
                "{p}"
            );
        }
        let started = acc.clone().with_pressure(3e6).unwrap();
        assert!((started.pressure(started.states()[0].initial).0 - 3e6).abs() < 1e-6);
    }

    #[test]
    fn partials_match_central_differences() {
        let port = [(1, 1.0, PortCausality::EffortOut)];
        // (a dead volume large against the differences' step, 6e-9 m³)
        let acc = Accumulator::new(1e6, 2e-3, 1.4)
            .unwrap()
            .with_empty_oil(1.5e9, 1e-4)
            .unwrap();
        for v in [-5e-4, -1e-5, 1e-4, 1.5e-3, 1.999e-3] {
            assert_eq!(check_partials(&acc, &port, &[0.0, 1e-3, v]), Ok(2), "{v}");
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(Accumulator::new(1e6, 0.0, 1.4).is_err());
        assert!(Accumulator::new(1e6, 1e-3, 0.9).is_err());
        assert!(Accumulator::new(1e6, 1e-3, f64::NAN).is_err());
        assert!(Accumulator::new(-2e5, 1e-3, 1.4).is_err());
        let a = Accumulator::new(1e6, 1e-3, 1.4).unwrap();
        assert!(a.clone().with_oil_volume(1e-3).is_err());
        assert!(a.clone().with_empty_oil(0.0, 1e-6).is_err());
        assert!(a.clone().with_atmosphere(-1.0).is_err());
        assert!(a.with_pressure(f64::INFINITY).is_err());
    }
}
