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
//! end of its chord in frame 0 (for hinged–hinged modes the deformed end), and `w{i}_mid`,
//! the deflection at mid-chord. Its states are `p[k]` and `q[k]`; the vector `<name>.q` is
//! what the other fields read. Each coordinate is also published by name, with its speed:
//! `q1`, `u1`, … for the joints and `qb{i}_{k}`, `ub{i}_{k}` for the modes of link i
//! (1-based, the design page's names); `qb{i}_{k}`/`ub{i}_{k}` exist for k = 1, 2, 3 even
//! when link i has fewer modes (a mode that is not modelled has zero amplitude), so result
//! columns survive a change of the number of modes.

use std::cell::RefCell;
use std::sync::Arc;

use bondgraph::{
    CausalRule, Element, Io, ParamError, PortCausality, PortSpec, Ports, SignalSpec, Slot, Stage,
    StateSpec,
};
use nalgebra::{DMatrix, DVector};

use crate::arm::PlanarArm;
use crate::kinetic_forces::solve;
use bondgraph::component_names;

/// The I-field of a [`PlanarArm`].
#[derive(Debug)]
pub struct ArmInertia {
    arm: Arc<PlanarArm>,
    q0: Vec<f64>,
    p0: Vec<f64>,
    p_nominal: Vec<f64>,
    mid: Vec<Option<crate::arm::Station>>,
    cache: RefCell<Option<Motion>>,
}

/// Everything computed at one state (p, q).
#[derive(Debug)]
struct Motion {
    key: Vec<f64>,
    m: DMatrix<f64>,
    u: DVector<f64>,
    e: DVector<f64>,
    mdot_u: DVector<f64>,
    kinetic: f64,
}

const OUT_U: usize = 0;
const OUT_UDOT: usize = 1;
const OUT_T: usize = 2;
const OUT_LINKS: usize = 3;
/// Named coordinates `qb{i}_{k}` are published at least up to this k.
const NAMED_MODES: usize = 3;

impl ArmInertia {
    /// (coordinate name, speed name, index in q or `None` for an unmodelled mode).
    fn named_coordinates(&self) -> Vec<(String, String, Option<usize>)> {
        let mut v: Vec<(String, String, Option<usize>)> = (1..=self.arm.n_links())
            .map(|i| (format!("q{i}"), format!("u{i}"), Some(i - 1)))
            .collect();
        for (i, l) in self.arm.links().iter().enumerate() {
            let n_modes = l.modes().len();
            for k in 1..=n_modes.max(NAMED_MODES) {
                let index = (k <= n_modes).then(|| self.arm.modal_offset(i) + k - 1);
                v.push((
                    format!("qb{}_{k}", i + 1),
                    format!("ub{}_{k}", i + 1),
                    index,
                ));
            }
        }
        v
    }

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
        if m.clone().cholesky().is_none() {
            return Err(ParamError::Shape {
                param: "links".into(),
                message: "the mass matrix is singular: every coordinate needs inertia (a massless link without a point mass?)".into(),
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
        Ok(Self {
            arm,
            q0,
            p0,
            p_nominal,
            mid,
            cache: RefCell::new(None),
        })
    }

    /// The arm.
    #[must_use]
    pub fn arm(&self) -> &Arc<PlanarArm> {
        &self.arm
    }

    fn motion<R>(&self, x: &[f64], f: impl FnOnce(&Motion) -> R) -> R {
        let mut cache = self.cache.borrow_mut();
        if let Some(m) = cache.as_ref().filter(|m| m.key == x) {
            return f(m);
        }
        f(cache.insert(self.compute(x)))
    }

    fn compute(&self, x: &[f64]) -> Motion {
        let n = self.arm.n();
        let (p, q) = x.split_at(n);
        let kin = self.arm.kinematics(q);
        let m = kin.mass_matrix();
        let pv = DVector::from_column_slice(p);
        let u = solve(m.clone(), &pv).unwrap_or_else(|| DVector::from_element(n, f64::NAN));
        let (e, mdot_u) = kin.kinetic_terms(u.as_slice());
        Motion {
            key: x.to_vec(),
            kinetic: 0.5 * u.dot(&pv),
            m,
            u,
            e,
            mdot_u,
        }
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
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        let n = self.arm.n();
        let named = self.named_coordinates();
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
        for (q, u, _) in &named {
            out.push(SignalSpec::scalar(q));
            out.push(SignalSpec::scalar(u));
        }
        out
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let n_out = OUT_LINKS + 3 * self.arm.n_links() + 2 * self.named_coordinates().len();
        let mut writes = vec![Slot::Flow(0), Slot::Output(OUT_U), Slot::Output(OUT_T)];
        writes.extend((OUT_LINKS..n_out).map(Slot::Output));
        vec![
            Stage {
                writes,
                reads: Vec::new(),
            },
            Stage {
                writes: vec![Slot::Output(OUT_UDOT)],
                reads: vec![Slot::Effort(0)],
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let x = io.states().to_vec();
        let n = self.arm.n();
        if stage == 0 {
            let (u, t) = self.motion(&x, |m| (m.u.clone(), m.kinetic));
            for k in 0..n {
                io.set_f_in(0, k, u[k]);
                io.set_y(OUT_U, k, u[k]);
            }
            io.set_y(OUT_T, 0, t);
            let pose = self.arm.pose(&x[n..]);
            for i in 0..self.arm.n_links() {
                let end = pose.origin(i + 1);
                let w = self.mid[i].as_ref().map_or(0.0, |s| pose.deflection(s));
                io.set_y(OUT_LINKS + 3 * i, 0, end.x);
                io.set_y(OUT_LINKS + 3 * i + 1, 0, end.y);
                io.set_y(OUT_LINKS + 3 * i + 2, 0, w);
            }
            let first = OUT_LINKS + 3 * self.arm.n_links();
            for (j, (_, _, index)) in self.named_coordinates().iter().enumerate() {
                let (q, v) = index.map_or((0.0, 0.0), |k| (x[n + k], u[k]));
                io.set_y(first + 2 * j, 0, q);
                io.set_y(first + 2 * j + 1, 0, v);
            }
        } else {
            let e = DVector::from_column_slice(io.effort(0));
            let udot = self.motion(&x, |m| {
                solve(m.m.clone(), &(e + &m.e - &m.mdot_u))
                    .unwrap_or_else(|| DVector::from_element(n, f64::NAN))
            });
            for k in 0..n {
                io.set_y(OUT_UDOT, k, udot[k]);
            }
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        let n = self.arm.n();
        let x = io.states().to_vec();
        self.motion(&x, |m| {
            for k in 0..n {
                dx[k] = io.e(0, k) + m.e[k];
                dx[n + k] = m.u[k];
            }
        });
    }
    fn stored_energy(&self, x: &[f64]) -> Option<f64> {
        Some(self.motion(x, |m| m.kinetic))
    }
}
