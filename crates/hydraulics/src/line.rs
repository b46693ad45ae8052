//! Line `hydraulics.line`: a pipe or hose of length ℓ and bore d as N lumped segments, each a
//! volume (C), a laminar resistance (R) and the oil's inertance (I), in one element.
//!
//! ```text
//!  a ─▶ C₁ ─ R₁,I₁ ─▶ C₂ ─ R₂,I₂ ─▶ … ─▶ C_N ─ R_N,I_N ─▶ b
//!
//!  C·dp_i/dt = q_(i−1) − q_i        q₀ = f_in,a (the flow into port a)
//!  I·dq_i/dt = p_i − p_(i+1) − R·q_i      p_(N+1) = e_b (the pressure at port b)
//!  e_a = p₁,   f_in,b = −q_N
//! ```
//!
//! per segment of length ℓ/N, with A = π d²/4:
//!
//! ```text
//! C = A·(ℓ/N)/β_eff,   1/β_eff = 1/β + d/(e·E)   (thin-walled pipe, wall thickness e, Young's modulus E)
//!                                or 1/β + k_w    (hose: volumetric expansion per pressure k_w)
//! R = 128·μ·(ℓ/N)/(π·d⁴)                            (Hagen–Poiseuille, laminar: Re = ρvd/μ < 2300)
//! I = ρ·(ℓ/N)/A
//! ```
//!
//! (Merritt, *Hydraulic Control Systems*, 1967, ch. 4 on lines and the effective bulk modulus
//! of a container; Manring, *Hydraulic Control Systems*, 2005, on pipe compliance and the
//! lumped line; the wall term is the thin-walled cylinder's radial expansion.) The lumped
//! chain is the wave equation discretised: waves travel at c = √(β_eff/ρ); the blocked line
//! (a closed, b held at a constant pressure) is a quarter-wave resonator, its lowest
//! frequency c/(4ℓ) for large N — the chain's own, 2N/T·sin(π/(2(2N+1))) with T = ℓ/c,
//! is low by about 1/(2N+1) relative. Friction is the steady laminar one (no frequency-
//! dependent friction), so higher modes are less damped than in a real line.
//!
//! States `p[1]…p[N]` (Pa, nominal `p_nominal`) and `q[1]…q[N]` (m³/s, nominal
//! `q_nominal`). Energy stored Σ C p²/2 + Σ I q²/2; dissipated Σ R q² ≥ 0. Volume: the oil
//! in the line changes by Σ C·Δp_i = ∫(f_in,a + f_in,b) dt exactly (linear compliance).
//!
//! Causality: fixed by the storages at the ends. Port `a` is a volume end: it **sets the
//! pressure** and receives the flow (bond it from a valve, a pump, a flow source, or a
//! 1-junction). Port `b` is an inertance end: it **receives the pressure** and sets the
//! flow (bond it to a chamber, an accumulator, a tank, or a 0-junction with one). A line
//! between two chambers has its `a` end at the upstream element that sets flow; turn it round
//! (swap `a` and `b` in the bonds) if the causality is the other way.

use bondgraph::kind::{BuildError, Change, KindDecl, ParamDecl, Params, Range, Simplification};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, Slot,
    Stage, StateSpec,
};

/// Largest number of segments (each adds two states).
pub const MAX_SEGMENTS: usize = 2000;

/// How the wall adds compliance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Wall {
    /// Rigid wall: β_eff = β.
    Rigid,
    /// Thin-walled pipe: wall thickness e (m) and Young's modulus E (Pa): adds d/(e·E).
    Pipe {
        /// Wall thickness e, m.
        thickness: f64,
        /// Young's modulus E, Pa.
        modulus: f64,
    },
    /// Hose: volumetric expansion per pressure k_w (1/Pa), i.e. (1/V)·dV/dp of the hose.
    Hose {
        /// Expansion coefficient k_w, 1/Pa.
        expansion: f64,
    },
}

/// Geometry and oil of a line; [`Line::new`] turns it into segments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineSpec {
    /// Length ℓ, m.
    pub length: f64,
    /// Bore d, m.
    pub diameter: f64,
    /// Number of segments N (≥ 1).
    pub segments: usize,
    /// Oil bulk modulus β, Pa.
    pub beta: f64,
    /// Oil density ρ, kg/m³ (default 870).
    pub rho: f64,
    /// Dynamic viscosity μ, Pa·s (default 0.028: ISO VG 32 at 40 °C); 0 for a lossless line.
    pub mu: f64,
    /// The wall's compliance (default rigid).
    pub wall: Wall,
}

impl LineSpec {
    /// A line of `length` (m) and bore `diameter` (m) in oil of modulus `beta` (Pa), with
    /// 10 segments, ρ = 870 kg/m³, μ = 0.028 Pa·s and a rigid wall.
    #[must_use]
    pub fn new(length: f64, diameter: f64, beta: f64) -> Self {
        Self {
            length,
            diameter,
            segments: 10,
            beta,
            rho: 870.0,
            mu: 0.028,
            wall: Wall::Rigid,
        }
    }

    /// Effective bulk modulus β_eff of oil and wall, Pa.
    #[must_use]
    pub fn beta_eff(&self) -> f64 {
        let wall = match self.wall {
            Wall::Rigid => 0.0,
            Wall::Pipe { thickness, modulus } => self.diameter / (thickness * modulus),
            Wall::Hose { expansion } => expansion,
        };
        1.0 / (1.0 / self.beta + wall)
    }

    /// Bore area A = π d²/4, m².
    #[must_use]
    pub fn area(&self) -> f64 {
        std::f64::consts::PI * self.diameter * self.diameter / 4.0
    }

    /// Total laminar resistance 128 μ ℓ/(π d⁴), Pa·s/m³.
    #[must_use]
    pub fn resistance(&self) -> f64 {
        crate::laminar::pipe_resistance(self.mu, self.length, self.diameter)
    }

    /// Total inertance ρ ℓ/A, kg/m⁴.
    #[must_use]
    pub fn inertance(&self) -> f64 {
        self.rho * self.length / self.area()
    }

    /// Total compliance A ℓ/β_eff, m³/Pa.
    #[must_use]
    pub fn compliance(&self) -> f64 {
        self.area() * self.length / self.beta_eff()
    }

    /// Speed of sound c = √(β_eff/ρ), m/s.
    #[must_use]
    pub fn wave_speed(&self) -> f64 {
        (self.beta_eff() / self.rho).sqrt()
    }
}

/// A line of N lumped segments (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    n: usize,
    /// Per segment: compliance, resistance, inertance.
    c: f64,
    r: f64,
    i: f64,
    p0: f64,
    p_nominal: f64,
    q_nominal: f64,
}

impl Line {
    /// The segments of `spec`, starting at pressure `p0` (Pa) and no flow.
    pub fn new(spec: &LineSpec, p0: f64) -> Result<Self, ParamError> {
        ParamError::positive("length", spec.length)?;
        ParamError::positive("diameter", spec.diameter)?;
        ParamError::positive("beta", spec.beta)?;
        ParamError::positive("rho", spec.rho)?;
        ParamError::non_negative("mu", spec.mu)?;
        ParamError::finite("p0", p0)?;
        match spec.wall {
            Wall::Rigid => {}
            Wall::Pipe { thickness, modulus } => {
                ParamError::positive("wall_thickness", thickness)?;
                ParamError::positive("e_wall", modulus)?;
            }
            Wall::Hose { expansion } => {
                ParamError::non_negative("k_wall", expansion)?;
            }
        }
        if !(1..=MAX_SEGMENTS).contains(&spec.segments) {
            return Err(ParamError::Shape {
                param: "segments".into(),
                message: format!(
                    "{} segments: give between 1 and {MAX_SEGMENTS}",
                    spec.segments
                ),
            });
        }
        let n = spec.segments as f64;
        Ok(Self {
            n: spec.segments,
            c: spec.compliance() / n,
            r: spec.resistance() / n,
            i: spec.inertance() / n,
            p0,
            p_nominal: 1e6,
            q_nominal: 1e-4,
        })
    }

    /// Set the typical pressure (Pa) and flow (m³/s) magnitudes: the absolute tolerances of
    /// the states are `atol` times these (defaults 1e6 Pa, 1e-4 m³/s).
    pub fn with_nominal(mut self, p_nominal: f64, q_nominal: f64) -> Result<Self, ParamError> {
        self.p_nominal = ParamError::positive("p_nominal", p_nominal)?;
        self.q_nominal = ParamError::positive("q_nominal", q_nominal)?;
        Ok(self)
    }

    /// Number of segments N.
    #[must_use]
    pub fn segments(&self) -> usize {
        self.n
    }

    /// Per-segment compliance C (m³/Pa), resistance R (Pa·s/m³) and inertance I (kg/m⁴).
    #[must_use]
    pub fn segment(&self) -> (f64, f64, f64) {
        (self.c, self.r, self.i)
    }
}

impl Element for Line {
    fn kind(&self) -> &str {
        "hydraulics.line"
    }
    fn energy_role(&self, _: usize) -> bondgraph::EnergyRole {
        // The segments' C and I store, their R (Hagen–Poiseuille) dissipates inside.
        bondgraph::EnergyRole::LossyStorage
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("a", 1), PortSpec::new("b", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Integral(vec![PortCausality::EffortOut, PortCausality::FlowOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        let p = (1..=self.n)
            .map(|k| StateSpec::new(&format!("p[{k}]"), self.p0).nominal(self.p_nominal));
        let q =
            (1..=self.n).map(|k| StateSpec::new(&format!("q[{k}]"), 0.0).nominal(self.q_nominal));
        p.chain(q).collect()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        vec![Stage {
            writes: vec![Slot::Effort(0), Slot::Flow(1)],
            reads: Vec::new(),
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let x = io.states();
        let (p1, qn) = (x[0], x[2 * self.n - 1]);
        io.set_e(0, 0, p1);
        io.set_f_in(1, 0, -qn);
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        let n = self.n;
        let x = io.states();
        let (p, q) = x.split_at(n);
        let (dp, dq) = dx.split_at_mut(n);
        let q_a = io.f_in(0, 0);
        let p_b = io.e(1, 0);
        for k in 0..n {
            let q_before = if k == 0 { q_a } else { q[k - 1] };
            dp[k] = (q_before - q[k]) / self.c;
            let p_after = if k + 1 == n { p_b } else { p[k + 1] };
            dq[k] = (p[k] - p_after - self.r * q[k]) / self.i;
        }
    }
    fn stage_partials(&self, _: usize, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        jac.set(jac.row(Slot::Effort(0), 0), jac.state_col(0), 1.0);
        jac.set(
            jac.row(Slot::Flow(1), 0),
            jac.state_col(2 * self.n - 1),
            -1.0,
        );
        true
    }
    fn derivative_partials(&self, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let n = self.n;
        let (ic, ii) = (1.0 / self.c, 1.0 / self.i);
        for k in 0..n {
            // dp_k = (q_(k−1) − q_k)/C
            let row = jac.derivative_row(k);
            let before = if k == 0 {
                jac.flow_col(0, 0)
            } else {
                jac.state_col(n + k - 1)
            };
            jac.set(row, before, ic);
            jac.set(row, jac.state_col(n + k), -ic);
            // dq_k = (p_k − p_(k+1) − R q_k)/I
            let row = jac.derivative_row(n + k);
            jac.set(row, jac.state_col(k), ii);
            let after = if k + 1 == n {
                jac.effort_col(1, 0)
            } else {
                jac.state_col(k + 1)
            };
            jac.set(row, after, -ii);
            jac.set(row, jac.state_col(n + k), -self.r * ii);
        }
        true
    }
    fn stored_energy(&self, x: &[f64]) -> Option<f64> {
        let (p, q) = x.split_at(self.n);
        let e_p: f64 = p.iter().map(|p| p * p).sum::<f64>() * self.c / 2.0;
        let e_q: f64 = q.iter().map(|q| q * q).sum::<f64>() * self.i / 2.0;
        Some(e_p + e_q)
    }
}

/// Kind `hydraulics.line`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.line",
    "pipe or hose, N lumped C–R–I segments (Hagen–Poiseuille, inertance ρℓ/A, wall compliance); port a sets p, b sets Q",
    &[
        ParamDecl::number("length", "m", "length ℓ").positive(),
        ParamDecl::number("diameter", "m", "bore d").positive(),
        ParamDecl::number("beta", "Pa", "oil bulk modulus β").positive(),
        ParamDecl::count("segments", "number of segments N, 1 … 2000 (two states each)")
            .range(Range::closed(1.0, 2000.0))
            .default(10.0),
        ParamDecl::number("rho", "kg/m³", "oil density").positive().default(870.0),
        ParamDecl::number("mu", "Pa·s", "dynamic viscosity (0: lossless)")
            .non_negative()
            .default(0.028),
        ParamDecl::number("wall_thickness", "m", "pipe wall thickness e (with e_wall)")
            .positive()
            .optional("rigid wall"),
        ParamDecl::number("e_wall", "Pa", "Young's modulus E of the pipe wall (with wall_thickness)")
            .positive()
            .optional("rigid wall"),
        ParamDecl::number("k_wall", "1/Pa", "hose: volumetric expansion per pressure")
            .non_negative()
            .optional("rigid wall"),
        ParamDecl::number("p0", "Pa", "initial pressure of every segment").default(0.0),
        ParamDecl::number("p_nominal", "Pa", "tolerance scale of the pressure states")
            .positive()
            .default(1e6),
        ParamDecl::number("q_nominal", "m³/s", "tolerance scale of the flow states")
            .positive()
            .default(1e-4),
    ],
    build,
)
.simplifications(&[Simplification::new(
    "one_segment",
    "one lumped C–R–I segment: the line's volume, loss and inertance, no wave",
    &[Change::Set("segments", "1")],
)])
.example("length = 5.0, diameter = 0.01, beta = 1.5e9, segments = 4");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    let pipe = p.has("wall_thickness") || p.has("e_wall");
    let wall = match (pipe, p.has("k_wall")) {
        (true, true) => return Err(BuildError::conflict(
            "k_wall",
            "give either a pipe wall (`wall_thickness`, `e_wall`) or a hose's `k_wall`, not both",
        )),
        (true, false) => {
            let (Some(thickness), Some(modulus)) =
                (p.optional("wall_thickness")?, p.optional("e_wall")?)
            else {
                let k = if p.has("e_wall") {
                    "wall_thickness"
                } else {
                    "e_wall"
                };
                return Err(BuildError::missing(
                    k,
                    "a pipe wall needs both `wall_thickness` and `e_wall`",
                ));
            };
            Wall::Pipe { thickness, modulus }
        }
        (false, true) => Wall::Hose {
            expansion: p.number("k_wall")?,
        },
        (false, false) => Wall::Rigid,
    };
    let spec = LineSpec {
        length: p.number("length")?,
        diameter: p.number("diameter")?,
        segments: p.count("segments")?,
        beta: p.number("beta")?,
        rho: p.number("rho")?,
        mu: p.number("mu")?,
        wall,
    };
    let line = Line::new(&spec, p.number("p0")?)?
        .with_nominal(p.number("p_nominal")?, p.number("q_nominal")?)?;
    Ok(Box::new(line))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Tank;
    use bondgraph::{
        assign_causality, check_partials, modes, simulate, BondGraph, EffortSource, FlowSource,
        Output, Param, Settings, StateEquations,
    };

    /// 5 m of 10 mm bore, steel wall 1.5 mm thick.
    fn spec(segments: usize) -> LineSpec {
        LineSpec {
            segments,
            wall: Wall::Pipe {
                thickness: 1.5e-3,
                modulus: 2.1e11,
            },
            ..LineSpec::new(5.0, 0.01, 1.5e9)
        }
    }

    /// The line between a flow source at `a` and `end` at `b`.
    fn circuit(line: Line, q_a: impl Into<Param>, tank: bool) -> StateEquations {
        let mut g = BondGraph::new();
        g.add("line", line).unwrap();
        g.add("pump", FlowSource::new(q_a)).unwrap();
        if tank {
            g.add(
                "end",
                Tank::new(0.0, 0.0)
                    .unwrap()
                    .with_nominal_volume(1e-6)
                    .unwrap(),
            )
            .unwrap();
        } else {
            g.add("end", EffortSource::new(0.0)).unwrap();
        }
        g.connect_names("pump", "line").unwrap(); // ports in order: a, then b
        g.connect_names("line", "end").unwrap();
        StateEquations::new(assign_causality(g).unwrap()).unwrap()
    }

    #[test]
    fn steady_laminar_flow_drops_r_total_times_q() {
        let s = spec(8);
        let q = 2e-5; // 0.25 m/s: Re = ρvd/μ = 78, laminar
        let mut eqs = circuit(Line::new(&s, 0.0).unwrap(), q, false);
        let outputs = vec![Output {
            name: "p_a".into(),
            probe: eqs.probe("line.a.e").unwrap(),
        }];
        let settings = Settings {
            t_end: 6.0,
            dt_out: 0.1,
            rtol: 1e-10,
            atol: 1e-10,
            ..Settings::default()
        };
        let x0 = eqs.initial_state();
        let run = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
        assert!(run.error.is_none(), "{:?}", run.error);
        let p_a = *run.trajectory.column("p_a").unwrap().last().unwrap();
        let expected = s.resistance() * q;
        eprintln!("Δp = {p_a:.6e} Pa, R·Q = {expected:.6e} Pa");
        // the waves decay with R/(2I) = 5.1 1/s: e^(−30) after 6 s
        assert!((p_a / expected - 1.0).abs() < 1e-8, "{p_a} vs {expected}");
    }

    #[test]
    fn blocked_line_rings_at_the_quarter_wave_frequency() {
        for n in [10, 50] {
            let s = LineSpec { mu: 0.0, ..spec(n) };
            let eqs = circuit(Line::new(&s, 0.0).unwrap(), 0.0, false);
            let x0 = eqs.initial_state();
            let m = modes(&eqs, 0.0, &x0).unwrap();
            let lowest = m
                .iter()
                .map(|m| m.damped_hz)
                .filter(|f| *f > 0.0)
                .fold(f64::INFINITY, f64::min);
            let t = s.length / s.wave_speed();
            let nf = n as f64;
            let chain = 2.0 * nf / t * (std::f64::consts::PI / (2.0 * (2.0 * nf + 1.0))).sin()
                / (2.0 * std::f64::consts::PI);
            let quarter = s.wave_speed() / (4.0 * s.length);
            eprintln!("N = {n}: {lowest:.4} Hz, chain {chain:.4} Hz, quarter wave {quarter:.4} Hz");
            assert!((lowest / chain - 1.0).abs() < 1e-9, "{lowest} vs {chain}");
            assert!((lowest / quarter - 1.0).abs() < 1.0 / (2.0 * nf), "N = {n}");
        }
    }

    #[test]
    fn volume_in_the_line_is_what_entered_less_what_left() {
        let s = spec(6);
        let line = Line::new(&s, 1e6).unwrap();
        let (c, _, _) = line.segment();
        let (q0, w) = (3e-5, 40.0);
        let q_a = Param::modulated(vec!["t".into()], move |t, _| q0 * (w * t).sin());
        let mut eqs = circuit(line, q_a, true);
        let mut outputs = vec![Output {
            name: "v_tank".into(),
            probe: eqs.probe("end.V").unwrap(),
        }];
        for k in 1..=6 {
            let name = format!("line.p[{k}]");
            outputs.push(Output {
                probe: eqs.probe(&name).unwrap(),
                name,
            });
        }
        let settings = Settings {
            t_end: 1.0,
            dt_out: 0.01,
            rtol: 1e-10,
            atol: 1e-10,
            ..Settings::default()
        };
        let x0 = eqs.initial_state();
        let run = simulate(&mut eqs, &x0, &settings, &outputs, vec![]);
        assert!(run.error.is_none(), "{:?}", run.error);
        let tr = &run.trajectory;
        let t = tr.column("t").unwrap();
        let v_tank = tr.column("v_tank").unwrap();
        let p: Vec<Vec<f64>> = (1..=6)
            .map(|k| tr.column(&format!("line.p[{k}]")).unwrap())
            .collect();
        let scale = q0 / w;
        let mut worst: f64 = 0.0;
        for k in 0..t.len() {
            let entered = q0 / w * (1.0 - (w * t[k]).cos());
            let stored: f64 = p.iter().map(|p| c * (p[k] - 1e6)).sum();
            worst = worst.max((entered - v_tank[k] - stored).abs() / scale);
        }
        eprintln!("worst volume imbalance {worst:.1e} of Q₀/ω");
        assert!(worst < 1e-7, "{worst:e}");
    }

    #[test]
    fn effective_modulus_segments_and_partials() {
        let s = spec(4);
        // 1/β_eff = 1/β + d/(e·E)
        let expected = 1.0 / (1.0 / 1.5e9 + 0.01 / (1.5e-3 * 2.1e11));
        assert!((s.beta_eff() / expected - 1.0).abs() < 1e-14);
        let hose = LineSpec {
            wall: Wall::Hose { expansion: 2e-9 },
            ..s
        };
        assert!((hose.beta_eff() - 1.0 / (1.0 / 1.5e9 + 2e-9)).abs() < 1e-3);
        let line = Line::new(&s, 0.0).unwrap();
        let (c, r, i) = line.segment();
        assert!((4.0 * r - 128.0 * 0.028 * 5.0 / (std::f64::consts::PI * 1e-8)).abs() < 1e-3);
        assert!((4.0 * i - 870.0 * 5.0 / s.area()).abs() < 1e-6);
        assert!((4.0 * c - s.area() * 5.0 / expected).abs() < 1e-24);
        let ports = [
            (1, 1.0, PortCausality::EffortOut),
            (1, -1.0, PortCausality::FlowOut),
        ];
        // e_a, f_a, e_b, f_b, p[1..4], q[1..4]
        let point = [
            0.0, 1e-5, 3e5, 0.0, 1e6, 9e5, 8e5, 7e5, 2e-5, -1e-5, 3e-5, 1e-5,
        ];
        assert_eq!(check_partials(&line, &ports, &point), Ok(2));
        assert_eq!(line.states().len(), 8);
        assert_eq!(line.states()[4].name, "q[1]");
    }

    #[test]
    fn rejects_bad_parameters() {
        let ok = spec(4);
        for bad in [
            LineSpec { length: 0.0, ..ok },
            LineSpec {
                diameter: -1.0,
                ..ok
            },
            LineSpec { segments: 0, ..ok },
            LineSpec {
                segments: MAX_SEGMENTS + 1,
                ..ok
            },
            LineSpec { mu: -1.0, ..ok },
            LineSpec {
                wall: Wall::Pipe {
                    thickness: 0.0,
                    modulus: 2e11,
                },
                ..ok
            },
        ] {
            assert!(Line::new(&bad, 0.0).is_err(), "{bad:?}");
        }
        assert!(Line::new(&ok, f64::NAN).is_err());
    }
}
