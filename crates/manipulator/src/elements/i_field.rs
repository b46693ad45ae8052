//! The manipulator I-field in momentum form (eqs. 43, 64): states p = M(q)u and q.
//!
//! One port of dimension n carries the generalized velocity u (integral causality: flow
//! out) and receives the total generalized force e applied to the arm (from the C-, R- and
//! actuator fields through the arm's 1-junction). The field holds the configuration q as
//! states of its own and adds the kinetic force `E = ∂T/∂q|_u` (eq. 44) internally:
//!
//! ```text
//! f_in = u = M(q)⁻¹ p,   ṗ = e + E(q, u),   q̇ = u.
//! ```
//!
//! With `T(p, q) = ½ pᵀ M⁻¹ p` this is power-consistent: `∂T/∂q|_p = −E`, so
//! `dT/dt = uᵀ(e + E) − E·u = uᵀ e`, the power on the port. The paper's bond 2 (q₂ = ∫f₂,
//! e₂ = −E) is folded into the field; eq. 43 reads `ṗ = E + G − K q − D u + τ` once the
//! junction sums the other fields.
//!
//! Publishes `u` (n), `udot` (n; `u̇ = M⁻¹(ṗ − Ṁu)`, computed in a second stage from the
//! effort received), `T` (kinetic energy), and per link i (1-based): `x_e{i}`, `y_e{i}`, the
//! end of its chord in frame 0 (for hinged–hinged modes the deformed end; with geometric
//! stiffening moved by the shortening of its own and the inboard chords), and `w{i}_mid`,
//! the deflection at mid-chord. Its states are `p[k]` and `q[k]`; the vector `<name>.q` is
//! what the other fields read. Each coordinate is also published by name, with its speed:
//! `q1`, `u1`, … for the joints and `qb{i}_{k}`, `ub{i}_{k}` for the modes of link i
//! (1-based, the scene's column names); `qb{i}_{k}`/`ub{i}_{k}` exist for k = 1, 2, 3 even
//! when link i has fewer modes (a mode that is not modelled has zero amplitude), so result
//! columns survive a change of the number of modes.
//!
//! # Stages
//! Stage 0 writes u (flow and signal); `derivatives` adds E. Both use one factorisation of
//! M(q) per state, which stage 1 (`udot`, from the effort received) reuses. Stages 2 (`T`,
//! `x_e{i}`, `y_e{i}`, `w{i}_mid`) and 3 (the named coordinates) write only signals, so the
//! right-hand side skips them unless another element reads them. Nothing allocates after
//! construction: M, its factor and the vectors live in a workspace.
//!
//! # Partials (for the exact Jacobian)
//! With `B = ∂²T/∂u∂q` (column k = `(∂M/∂q_k) u`) and `H = ∂²T/∂q²`
//! ([`hessians`](crate::hessians)): `∂u/∂p = M⁻¹`, `∂u/∂q = −M⁻¹B`, and
//! `∂ṗ/∂e = I`, `∂ṗ/∂p = BᵀM⁻¹`, `∂ṗ/∂q = H − BᵀM⁻¹B` (since `∂E/∂u = Bᵀ`). Stages 0, 2 and 3
//! and the derivatives give them analytically; `udot` (stage 1) is left to the core.

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{
    component_names, CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec,
    Ports, SignalSpec, Slot, Stage, StateSpec,
};
use nalgebra::{DMatrix, DVector};

use crate::arm::z_cross;

use super::at_last_q::AtLastQ;
use crate::arm::{Frames, PlanarArm, Station};
use crate::cholesky::Cholesky;
use crate::kinematics::ArmKinematics;

/// The I-field of a [`PlanarArm`].
#[derive(Debug)]
pub struct ArmInertia {
    arm: Arc<PlanarArm>,
    q0: Vec<f64>,
    p0: Vec<f64>,
    p_nominal: Vec<f64>,
    mid: Vec<Option<Station>>,
    /// With geometric stiffening, the chord end of each link as a station (x = L), which
    /// moves with the shortening of its own and the inboard chords; empty without.
    ends: Vec<Station>,
    /// (coordinate name, speed name, index in q or `None` for an unmodelled mode).
    named: Vec<(String, String, Option<usize>)>,
    /// With a rolling base ([`base`](crate::base)): the signals θ̇ and θ̈. The state is then
    /// the absolute momentum `p = M(q)(u + θ̇ e₁)`, and the flow the relative speed u.
    roll: Option<[String; 2]>,
    ws: RefCell<Motion>,
}

/// Everything computed at one state x = (p, q), in buffers allocated once: what the
/// right-hand side needs at the last state, Ṁu at the last state `udot` was asked at, the
/// partials at the state of the last partials; the frames they are computed in and scratch.
#[derive(Debug)]
struct Motion {
    frames: Frames,
    at_state: AtLastQ<AtState>,
    mdot_u: AtLastQ<Vec<f64>>,
    partials: AtLastQ<Partials>,
    udot: Vec<f64>,
}

/// M, its factor, u = M⁻¹p, E and T at one state.
#[derive(Debug)]
struct AtState {
    m: DMatrix<f64>,
    factor: Cholesky,
    u: Vec<f64>,
    e: Vec<f64>,
    kinetic: f64,
}

/// M⁻¹, B, M⁻¹B and `H − BᵀM⁻¹B` at one state, and the rows of the partials as the
/// LocalJacobian takes them (its state columns p then q are contiguous).
#[derive(Debug)]
struct Partials {
    minv: DMatrix<f64>,
    b: DMatrix<f64>,
    minv_b: DMatrix<f64>,
    dpdot_dq: DMatrix<f64>,
    /// Row-major n × 2n: row k is `∂u_k/∂(p, q)` = (row k of M⁻¹, row k of −M⁻¹B).
    speed: Vec<f64>,
    /// Row-major n × 2n: row r is `∂ṗ_r/∂(p, q)` = (column r of M⁻¹B, row r of `H − BᵀM⁻¹B`).
    pdot: Vec<f64>,
}

const OUT_U: usize = 0;
const OUT_UDOT: usize = 1;
const OUT_T: usize = 2;
const OUT_LINKS: usize = 3;
/// Named coordinates `qb{i}_{k}` are published at least up to this k.
const NAMED_MODES: usize = 3;

impl Motion {
    fn new(arm: &PlanarArm) -> Self {
        let n = arm.n();
        Self {
            frames: arm.frames(),
            at_state: AtLastQ::new(
                2 * n,
                AtState {
                    m: DMatrix::zeros(n, n),
                    factor: Cholesky::new(n),
                    u: vec![0.0; n],
                    e: vec![0.0; n],
                    kinetic: 0.0,
                },
            ),
            mdot_u: AtLastQ::new(2 * n, vec![0.0; n]),
            partials: AtLastQ::new(
                2 * n,
                Partials {
                    minv: DMatrix::zeros(n, n),
                    b: DMatrix::zeros(n, n),
                    minv_b: DMatrix::zeros(n, n),
                    dpdot_dq: DMatrix::zeros(n, n),
                    speed: vec![0.0; 2 * n * n],
                    pdot: vec![0.0; 2 * n * n],
                },
            ),
            udot: vec![0.0; n],
        }
    }

    /// What is computed at the state x, and x.
    fn state(&mut self, arm: &PlanarArm, x: &[f64]) -> (&[f64], &AtState) {
        let Self {
            frames, at_state, ..
        } = self;
        AtState::at(at_state, frames, arm, x)
    }

    /// What is computed at the state x, and the partials there.
    fn partials(&mut self, arm: &PlanarArm, x: &[f64]) -> (&AtState, &Partials) {
        let Self {
            frames,
            at_state,
            partials,
            ..
        } = self;
        let (_, state) = AtState::at(at_state, frames, arm, x);
        let (_, partials) =
            partials.get_or_update(x, |x, partials| partials.compute(arm, x, state, frames));
        (state, partials)
    }

    /// `u̇ = M⁻¹(e + E − Ṁu)` at the state x with the effort e received (`effort(k)`).
    fn accelerations(
        &mut self,
        arm: &PlanarArm,
        x: &[f64],
        effort: impl Fn(usize) -> f64,
    ) -> &[f64] {
        let Self {
            frames,
            at_state,
            mdot_u,
            udot,
            ..
        } = self;
        let (_, state) = AtState::at(at_state, frames, arm, x);
        let (_, mdot_u) = mdot_u.get_or_update(x, |x, mdot_u| {
            let kin = ArmKinematics::new(arm.pose_in(&x[arm.n()..], frames));
            // (E again into udot, overwritten below)
            kin.kinetic_terms_into(&state.u, udot, Some(mdot_u));
        });
        for (k, a) in udot.iter_mut().enumerate() {
            *a = effort(k) + state.e[k] - mdot_u[k];
        }
        state.factor.solve_in_place(udot);
        udot
    }
}

impl AtState {
    /// The value of `cache` at the state x (updated unless x is its last state), and x.
    fn at<'c>(
        cache: &'c mut AtLastQ<Self>,
        frames: &mut Frames,
        arm: &PlanarArm,
        x: &[f64],
    ) -> (&'c [f64], &'c Self) {
        cache.get_or_update(x, |x, s| s.compute(arm, x, frames))
    }

    /// M, its factor, u = M⁻¹p, E and T at the state x = (p, q).
    fn compute(&mut self, arm: &PlanarArm, x: &[f64], frames: &mut Frames) {
        let Self {
            m,
            factor,
            u,
            e,
            kinetic,
        } = self;
        let (p, q) = x.split_at(arm.n());
        let kin = ArmKinematics::new(arm.pose_in(q, frames));
        kin.mass_matrix_into(m);
        factor.factor(m);
        u.copy_from_slice(p);
        factor.solve_in_place(u);
        kin.kinetic_terms_into(u, e, None);
        *kinetic = 0.5 * u.iter().zip(p).map(|(a, b)| a * b).sum::<f64>();
    }
}

impl Partials {
    /// M⁻¹, B, M⁻¹B and `H − BᵀM⁻¹B` at the state x, with what is computed there.
    fn compute(&mut self, arm: &PlanarArm, x: &[f64], state: &AtState, frames: &mut Frames) {
        let Self {
            minv,
            b,
            minv_b,
            dpdot_dq,
            speed,
            pdot,
        } = self;
        let AtState { factor, u, .. } = state;
        let n = arm.n();
        let kin = ArmKinematics::new(arm.pose_in(&x[n..], frames));
        kin.kinetic_partials_into(u, b, dpdot_dq);
        for (k, col) in minv.as_mut_slice().chunks_mut(n).enumerate() {
            factor.inverse_column(k, col);
        }
        minv_b.copy_from(b);
        for col in minv_b.as_mut_slice().chunks_mut(n) {
            // from the first entry that is not +0 (column 0 of B is zero for a free base joint)
            let first = col.iter().position(|v| v.to_bits() != 0).unwrap_or(n);
            factor.solve_from(first, col);
        }
        // (BᵀM⁻¹B)_rc: columns r of B and c of M⁻¹B, contiguous (column-major)
        let (bs, xs) = (b.as_slice(), minv_b.as_slice());
        for (xc, dc) in xs
            .chunks_exact(n)
            .zip(dpdot_dq.as_mut_slice().chunks_exact_mut(n))
        {
            for (br, d) in bs.chunks_exact(n).zip(dc) {
                let bt_x: f64 = br.iter().zip(xc).map(|(p, x)| p * x).sum();
                *d -= bt_x;
            }
        }
        let (ms, hs, w) = (minv.as_slice(), dpdot_dq.as_slice(), 2 * n); // the rows set
        for (c, ((mc, xc), hc)) in ms
            .chunks_exact(n)
            .zip(xs.chunks_exact(n))
            .zip(hs.chunks_exact(n))
            .enumerate()
        {
            for k in 0..n {
                (speed[w * k + c], speed[w * k + n + c]) = (mc[k], -xc[k]);
                pdot[w * k + n + c] = hc[k];
            }
            pdot[w * c..w * c + n].copy_from_slice(xc);
        }
    }
}

/// Entries (row, state column c) = `values[c]`, c = 0, 1, … (the state columns are contiguous).
fn set_row(jac: &mut LocalJacobian<'_>, row: usize, values: &[f64]) {
    let first = jac.state_col(0);
    for (c, &v) in values.iter().enumerate() {
        jac.set(row, first + c, v);
    }
}

impl ArmInertia {
    /// The I-field of `arm` starting at configuration `q0` with speeds `u0` (p₀ = M(q₀)u₀).
    pub fn new(arm: Arc<PlanarArm>, q0: Vec<f64>, u0: Vec<f64>) -> Result<Self, ParamError> {
        let n = arm.n();
        for (name, v) in [("q0", &q0), ("u0", &u0)] {
            if v.len() != n {
                return Err(ParamError::Shape {
                    param: name.into(),
                    message: format!(
                        "needs {n} values ({}), got {}",
                        arm.coordinate_names().join(", "),
                        v.len()
                    ),
                });
            }
            for &x in v {
                ParamError::finite(name, x)?;
            }
        }
        let m = arm.kinematics(&q0).mass_matrix();
        if !Cholesky::new(n).factor(&m) {
            // name the coordinates without inertia (an empty pendulum: payload mass 0)
            let largest = (0..n).fold(0.0_f64, |a, k| a.max(m[(k, k)].abs()));
            let names = arm.coordinate_names();
            let without: Vec<String> = (0..n)
                .filter(|&k| m[(k, k)].abs() <= 1e-12 * largest)
                .filter_map(|k| names.get(k).map(ToString::to_string))
                .collect();
            let which = if without.is_empty() {
                String::new()
            } else {
                format!(" ({} has none)", without.join(", "))
            };
            return Err(ParamError::Shape {
                param: "links".into(),
                message: format!("the mass matrix is singular: every coordinate needs inertia{which}; a massless link needs a point mass (a pendulum with mass 0, an empty hook: give it the hook's own mass)"),
            });
        }
        let p0 = (&m * DVector::from_column_slice(&u0))
            .iter()
            .copied()
            .collect();
        let p_nominal = (0..n).map(|k| m[(k, k)].max(f64::MIN_POSITIVE)).collect();
        let mid = arm
            .links()
            .iter()
            .enumerate()
            .map(|(i, l)| {
                (!l.is_rigid())
                    .then(|| arm.station(i, l.length() / 2.0).ok())
                    .flatten()
            })
            .collect();
        let ends = if arm.has_geometric_stiffening() {
            (0..arm.n_links())
                .map(|i| arm.station(i, arm.links()[i].length()))
                .collect::<Result<_, _>>()?
        } else {
            Vec::new()
        };
        let mut named: Vec<(String, String, Option<usize>)> = (1..=arm.n_links())
            .map(|i| (format!("q{i}"), format!("u{i}"), Some(i - 1)))
            .collect();
        for (i, l) in arm.links().iter().enumerate() {
            let n_modes = l.modes().len();
            for k in 1..=n_modes.max(NAMED_MODES) {
                let index = (k <= n_modes).then(|| arm.modal_offset(i) + k - 1);
                named.push((
                    format!("qb{}_{k}", i + 1),
                    format!("ub{}_{k}", i + 1),
                    index,
                ));
            }
        }
        Ok(Self {
            ws: RefCell::new(Motion::new(&arm)),
            arm,
            q0,
            p0,
            p_nominal,
            mid,
            ends,
            named,
            roll: None,
        })
    }

    /// On a rolling base: the state becomes the absolute momentum `p = M(q)(u + θ̇ e₁)`
    /// (starting with `p₀ = M(q₀)(u₀ + omega0 e₁)`), the flow and `q̇` the relative speed
    /// `M⁻¹p − θ̇ e₁`, and `udot` the relative acceleration; θ̇ and θ̈ are read from the
    /// signals `omega` and `alpha` ([`base`](crate::base)).
    #[must_use]
    pub fn on_rolling_base(mut self, omega: String, alpha: String, omega0: f64) -> Self {
        // p₀ = M u₀ + omega0 M e₁
        let m = self.arm.kinematics(&self.q0).mass_matrix();
        for (k, p) in self.p0.iter_mut().enumerate() {
            *p += omega0 * m[(k, 0)];
        }
        self.roll = Some([omega, alpha]);
        self
    }

    /// θ̇ now (0 without a rolling base).
    #[inline]
    fn omega(&self, io: &Io<'_>) -> f64 {
        if self.roll.is_some() {
            io.u(0)
        } else {
            0.0
        }
    }

    /// The arm.
    #[must_use]
    pub fn arm(&self) -> &Arc<PlanarArm> {
        &self.arm
    }

    fn first_named_output(&self) -> usize {
        OUT_LINKS + 3 * self.arm.n_links()
    }
}

impl Element for ArmInertia {
    fn kind(&self) -> &str {
        "manipulator.i_field"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", self.arm.n())])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Integral(vec![PortCausality::FlowOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        let n = self.arm.n();
        let p = component_names("p", n)
            .into_iter()
            .zip(&self.p0)
            .zip(&self.p_nominal)
            .map(|((name, &p), &nom)| StateSpec::new(&name, p).nominal(nom));
        let q = component_names("q", n)
            .into_iter()
            .zip(&self.q0)
            .map(|(name, &q)| StateSpec::new(&name, q));
        p.chain(q).collect()
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.roll
            .iter()
            .flatten()
            .map(|s| SignalSpec::scalar(s))
            .collect()
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        let n = self.arm.n();
        let mut out = vec![
            SignalSpec {
                name: "u".into(),
                dim: n,
            },
            SignalSpec {
                name: "udot".into(),
                dim: n,
            },
            SignalSpec::scalar("T"),
        ];
        for i in 1..=self.arm.n_links() {
            out.push(SignalSpec::scalar(&format!("x_e{i}")));
            out.push(SignalSpec::scalar(&format!("y_e{i}")));
            out.push(SignalSpec::scalar(&format!("w{i}_mid")));
        }
        for (q, u, _) in &self.named {
            out.push(SignalSpec::scalar(q));
            out.push(SignalSpec::scalar(u));
        }
        out
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let first = self.first_named_output();
        let mut geometry = vec![Slot::Output(OUT_T)];
        geometry.extend((OUT_LINKS..first).map(Slot::Output));
        let (omega, alpha) = if self.roll.is_some() {
            (vec![Slot::Input(0)], vec![Slot::Input(1)])
        } else {
            (Vec::new(), Vec::new())
        };
        let mut udot = vec![Slot::Effort(0)];
        udot.extend(alpha);
        vec![
            Stage {
                writes: vec![Slot::Flow(0), Slot::Output(OUT_U)],
                reads: omega.clone(),
            },
            Stage {
                writes: vec![Slot::Output(OUT_UDOT)],
                reads: udot,
            },
            Stage {
                writes: geometry,
                reads: Vec::new(),
            },
            Stage {
                writes: (first..first + 2 * self.named.len())
                    .map(Slot::Output)
                    .collect(),
                reads: omega,
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let n = self.arm.n();
        let mut ws = self.ws.borrow_mut();
        match stage {
            0 => {
                let (_, state) = ws.state(&self.arm, io.states());
                for (k, &uk) in state.u.iter().enumerate() {
                    io.set_f_in(0, k, uk);
                    io.set_y(OUT_U, k, uk);
                }
                if self.roll.is_some() {
                    let u1 = state.u[0] - io.u(0);
                    io.set_f_in(0, 0, u1);
                    io.set_y(OUT_U, 0, u1);
                }
            }
            1 => {
                let udot = ws.accelerations(&self.arm, io.states(), |k| io.e(0, k));
                for (k, &a) in udot.iter().enumerate() {
                    io.set_y(OUT_UDOT, k, a);
                }
                if self.roll.is_some() {
                    io.set_y(OUT_UDOT, 0, udot[0] - io.u(1));
                }
            }
            2 => {
                let Motion {
                    frames, at_state, ..
                } = &mut *ws;
                let (x, state) = AtState::at(at_state, frames, &self.arm, io.states());
                io.set_y(OUT_T, 0, state.kinetic);
                let pose = self.arm.pose_in(&x[n..], frames);
                for i in 0..self.arm.n_links() {
                    let end = self
                        .ends
                        .get(i)
                        .map_or_else(|| pose.origin(i + 1), |s| pose.position(s));
                    let w = self.mid[i].as_ref().map_or(0.0, |s| pose.deflection(s));
                    io.set_y(OUT_LINKS + 3 * i, 0, end.x);
                    io.set_y(OUT_LINKS + 3 * i + 1, 0, end.y);
                    io.set_y(OUT_LINKS + 3 * i + 2, 0, w);
                }
            }
            _ => {
                let omega = self.omega(io);
                let (x, state) = ws.state(&self.arm, io.states());
                let first = self.first_named_output();
                for (j, (_, _, index)) in self.named.iter().enumerate() {
                    let (q, v) = index.map_or((0.0, 0.0), |k| (x[n + k], state.u[k]));
                    let v = if index == &Some(0) && self.roll.is_some() {
                        v - omega
                    } else {
                        v
                    };
                    io.set_y(first + 2 * j, 0, q);
                    io.set_y(first + 2 * j + 1, 0, v);
                }
            }
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        let n = self.arm.n();
        let mut ws = self.ws.borrow_mut();
        let (_, state) = ws.state(&self.arm, io.states());
        for k in 0..n {
            dx[k] = io.e(0, k) + state.e[k];
            dx[n + k] = state.u[k];
        }
        if self.roll.is_some() {
            dx[n] -= io.u(0);
        }
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let n = self.arm.n();
        let mut ws = self.ws.borrow_mut();
        let Motion {
            frames,
            at_state,
            partials,
            ..
        } = &mut *ws;
        let (x, state) = AtState::at(at_state, frames, &self.arm, io.states());
        let (_, d) = partials.get_or_update(x, |x, d| d.compute(&self.arm, x, state, frames));
        // ∂u_k/∂(p, q) into row `row`.
        let speed_row = |jac: &mut LocalJacobian<'_>, row: usize, k: usize| {
            set_row(jac, row, &d.speed[2 * n * k..2 * n * (k + 1)]);
        };
        match stage {
            0 => {
                for k in 0..n {
                    speed_row(jac, jac.row(Slot::Flow(0), k), k);
                    speed_row(jac, jac.row(Slot::Output(OUT_U), k), k);
                }
                if self.roll.is_some() {
                    for slot in [Slot::Flow(0), Slot::Output(OUT_U)] {
                        jac.set(jac.row(slot, 0), jac.input_col(0, 0), -1.0);
                    }
                }
            }
            1 => return false,
            2 => {
                // T: ∂T/∂p = u, ∂T/∂q|_p = −E
                let row = jac.row(Slot::Output(OUT_T), 0);
                for c in 0..n {
                    jac.set(row, jac.state_col(c), state.u[c]);
                    jac.set(row, jac.state_col(n + c), -state.e[c]);
                }
                let pose = self.arm.pose_in(&x[n..], frames);
                for i in 0..self.arm.n_links() {
                    let (rx, ry) = (
                        jac.row(Slot::Output(OUT_LINKS + 3 * i), 0),
                        jac.row(Slot::Output(OUT_LINKS + 3 * i + 1), 0),
                    );
                    if let Some(s) = self.ends.get(i) {
                        // the shortened chord end: its columns, shortening included
                        pose.point_jacobian(s, |k, d| {
                            jac.set(rx, jac.state_col(n + k), d.x);
                            jac.set(ry, jac.state_col(n + k), d.y);
                        });
                    } else {
                        let end = pose.origin(i + 1);
                        for j in 0..=i {
                            let d = z_cross(&(end - pose.origin(j)));
                            jac.set(rx, jac.state_col(n + j), d.x);
                            jac.set(ry, jac.state_col(n + j), d.y);
                        }
                    }
                    if let Some(s) = &self.mid[i] {
                        let rw = jac.row(Slot::Output(OUT_LINKS + 3 * i + 2), 0);
                        let o = self.arm.modal_offset(i);
                        for (k, psi) in s.psi.iter().enumerate() {
                            jac.set(rw, jac.state_col(n + o + k), *psi);
                        }
                    }
                }
            }
            _ => {
                let first = self.first_named_output();
                for (j, (_, _, index)) in self.named.iter().enumerate() {
                    if let Some(k) = *index {
                        let row = jac.row(Slot::Output(first + 2 * j), 0);
                        jac.set(row, jac.state_col(n + k), 1.0);
                        let speed = jac.row(Slot::Output(first + 2 * j + 1), 0);
                        speed_row(jac, speed, k);
                        if k == 0 && self.roll.is_some() {
                            jac.set(speed, jac.input_col(0, 0), -1.0);
                        }
                    }
                }
            }
        }
        true
    }
    fn derivative_partials(&self, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let n = self.arm.n();
        let mut ws = self.ws.borrow_mut();
        let (_, d) = ws.partials(&self.arm, io.states());
        for r in 0..n {
            // ṗ = e + E(q, u(p, q)), q̇ = u(p, q)
            let (row, w) = (jac.derivative_row(r), 2 * n * r..2 * n * (r + 1));
            jac.set(row, jac.effort_col(0, r), 1.0);
            set_row(jac, row, &d.pdot[w.clone()]);
            set_row(jac, jac.derivative_row(n + r), &d.speed[w]);
        }
        if self.roll.is_some() {
            jac.set(jac.derivative_row(n), jac.input_col(0, 0), -1.0);
        }
        true
    }
    fn stored_energy(&self, x: &[f64]) -> Option<f64> {
        let mut ws = self.ws.borrow_mut();
        Some(ws.state(&self.arm, x).1.kinetic)
    }
}
