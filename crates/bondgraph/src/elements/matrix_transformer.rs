//! Matrix-modulated transformer `MTF` (multibond): e₁ = T·e₂, f_in₂ = −Tᵀ·f_in₁.
//!
//! `T` is n₁×n₂ and may depend on time and signals, e.g. the actuator Jacobian τ_b(q) of the
//! paper's eq. 66 (n₁ = 9 generalized coordinates, n₂ = 2 cylinders). Power is conserved
//! for every `T`: e₁ᵀf_in₁ + e₂ᵀf_in₂ = e₂ᵀTᵀf_in₁ − e₂ᵀTᵀf_in₁ = 0.
//!
//! Causality: fixed, port 1 effort out and port 2 flow out (a non-square `T` cannot be
//! inverted, so the other orientation is not offered).

use std::cell::RefCell;
use std::fmt;

use nalgebra::DMatrix;

use crate::bond::PortCausality;
use crate::element::{CausalRule, Element, Io, PortSpec, Ports, SignalSpec, Slot, Stage};
use crate::error::ParamError;
use crate::kind::{BuildError, KindDecl, ParamDecl, Params};
use crate::local_jacobian::LocalJacobian;

/// The modulus law: fill `t` (n₁×n₂) from time and the element's inputs.
pub type ModulusLaw = Box<dyn Fn(&Io<'_>, &mut DMatrix<f64>)>;

/// Widest port whose values [`apply_effort`] and [`apply_flow`] gather on the stack.
const MAX_LOCAL: usize = 16;

/// `e₁ = T·e₂` on ports 0 and 1 of `io` (for matrix MTFs of other crates too).
pub fn apply_effort(io: &mut Io<'_>, t: &DMatrix<f64>) {
    let (n1, n2) = t.shape();
    if n2 > MAX_LOCAL || n2 == 0 || n1 == 0 {
        for i in 0..n1 {
            let e: f64 = (0..n2).map(|j| t[(i, j)] * io.e(1, j)).sum();
            io.set_e(0, i, e);
        }
        return;
    }
    // e₂ on the stack, then e₁ += T_:j·e₂_j column by column (T is column-major): each
    // e₁_i is the sum Σ_j T_ij e₂_j in the same order as `Iterator::sum`, which starts at
    // −0 (−0 + a = a exactly, so the first term is stored)
    let (o1, o2) = (io.layout.ports[0].offset, io.layout.ports[1].offset);
    let mut buf = [0.0; MAX_LOCAL];
    let e2 = &mut buf[..n2];
    e2.copy_from_slice(&io.effort[o2..o2 + n2]);
    let e1 = &mut io.effort[o1..o1 + n1];
    let mut cols = t.as_slice().chunks_exact(n1).zip(&*e2);
    if let Some((col, &e)) = cols.next() {
        for (y, tij) in e1.iter_mut().zip(col) {
            *y = tij * e;
        }
    }
    for (col, &e) in cols {
        for (y, tij) in e1.iter_mut().zip(col) {
            *y += tij * e;
        }
    }
}

/// `f_in₂ = −Tᵀ·f_in₁` on ports 0 and 1 of `io`.
pub fn apply_flow(io: &mut Io<'_>, t: &DMatrix<f64>) {
    let (n1, n2) = t.shape();
    if n1 > MAX_LOCAL || n1 == 0 {
        for j in 0..n2 {
            let f: f64 = (0..n1).map(|i| t[(i, j)] * io.f_in(0, i)).sum();
            io.set_f_in(1, j, -f);
        }
        return;
    }
    // f_in₁ on the stack, then column j of T (contiguous) times it: Σ_i T_ij f_in₁_i
    let (p1, p2) = (&io.layout.ports[0], &io.layout.ports[1]);
    let mut buf = [0.0; MAX_LOCAL];
    let f1 = &mut buf[..n1];
    for (b, f) in f1.iter_mut().zip(&io.flow[p1.offset..p1.offset + n1]) {
        *b = p1.sign * f;
    }
    let s2 = p2.sign;
    for (col, f2) in t
        .as_slice()
        .chunks_exact(n1)
        .zip(&mut io.flow[p2.offset..p2.offset + n2])
    {
        let f: f64 = col.iter().zip(&*f1).map(|(tij, f)| tij * f).sum();
        *f2 = s2 * -f;
    }
}

/// The partials of [`apply_effort`] with respect to e₂ (∂e₁/∂e₂ = T), for the stage writing
/// `Slot::Effort(0)`; the modulation's partials are the caller's.
pub fn effort_partials(jac: &mut LocalJacobian<'_>, t: &DMatrix<f64>) {
    for i in 0..t.nrows() {
        let row = jac.row(Slot::Effort(0), i);
        for j in 0..t.ncols() {
            jac.set(row, jac.effort_col(1, j), t[(i, j)]);
        }
    }
}

/// The partials of [`apply_flow`] with respect to f_in₁ (∂f_in₂/∂f_in₁ = −Tᵀ), for the stage
/// writing `Slot::Flow(1)`; the modulation's partials are the caller's.
pub fn flow_partials(jac: &mut LocalJacobian<'_>, t: &DMatrix<f64>) {
    for j in 0..t.ncols() {
        let row = jac.row(Slot::Flow(1), j);
        for i in 0..t.nrows() {
            jac.set(row, jac.flow_col(0, i), -t[(i, j)]);
        }
    }
}

/// Matrix MTF.
pub struct MatrixTransformer {
    n1: usize,
    n2: usize,
    inputs: Vec<SignalSpec>,
    law: ModulusLaw,
    scratch: RefCell<DMatrix<f64>>,
}

impl MatrixTransformer {
    /// An MTF with an n₁×n₂ modulus computed by `law` from the signals `inputs`.
    pub fn new(
        n1: usize,
        n2: usize,
        inputs: Vec<SignalSpec>,
        law: ModulusLaw,
    ) -> Result<Self, ParamError> {
        if n1 == 0 || n2 == 0 {
            return Err(ParamError::Shape {
                param: "T".into(),
                message: format!("modulus must be at least 1×1, got {n1}×{n2}"),
            });
        }
        Ok(Self {
            n1,
            n2,
            inputs,
            law,
            scratch: RefCell::new(DMatrix::zeros(n1, n2)),
        })
    }

    /// A constant matrix modulus.
    pub fn constant(t: DMatrix<f64>) -> Result<Self, ParamError> {
        if t.iter().any(|v| !v.is_finite()) {
            return Err(ParamError::Shape {
                param: "T".into(),
                message: "entries must be finite".into(),
            });
        }
        let (n1, n2) = t.shape();
        Self::new(n1, n2, Vec::new(), Box::new(move |_, m| m.copy_from(&t)))
    }
}

impl fmt::Debug for MatrixTransformer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "MatrixTransformer({}×{}, inputs {:?})",
            self.n1, self.n2, self.inputs
        )
    }
}

impl Element for MatrixTransformer {
    fn kind(&self) -> &str {
        "MTF"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![
            PortSpec::new("1", self.n1),
            PortSpec::new("2", self.n2),
        ])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![PortCausality::EffortOut, PortCausality::FlowOut])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.inputs.clone()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let modulation: Vec<Slot> = (0..self.inputs.len()).map(Slot::Input).collect();
        let with = |s: Slot| {
            std::iter::once(s)
                .chain(modulation.iter().copied())
                .collect()
        };
        vec![
            Stage {
                writes: vec![Slot::Effort(0)],
                reads: with(Slot::Effort(1)),
            },
            Stage {
                writes: vec![Slot::Flow(1)],
                reads: with(Slot::Flow(0)),
            },
        ]
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let mut t = self.scratch.borrow_mut();
        (self.law)(io, &mut t);
        if stage == 0 {
            apply_effort(io, &t);
        } else {
            apply_flow(io, &t);
        }
    }
    /// Exact for a constant modulus; a modulated one (a closure of the element's `Io`) is
    /// differenced by the core.
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        if !self.inputs.is_empty() {
            return false;
        }
        let mut t = self.scratch.borrow_mut();
        (self.law)(io, &mut t);
        if stage == 0 {
            effort_partials(jac, &t);
        } else {
            flow_partials(jac, &t);
        }
        true
    }
}

/// Kind `MTF`: a modulated transformer, scalar (`m`) or matrix (`T`, e₁ = T·e₂).
pub const KIND: KindDecl = KindDecl::element(
    "MTF",
    "modulated transformer: m = m(signals), or a matrix T(signals) with e1 = T·e2",
    &[
        ParamDecl::modulated("m", "", "scalar modulus (may read signals)")
            .optional("give `m` or `T`"),
        ParamDecl::matrix("T", "", "modulus matrix, rows of expressions (e1 = T·e2)")
            .optional("give `m` or `T`"),
    ],
    build,
)
.example("m = \"1 + 0.1*t\"");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    if !p.has("T") {
        if !p.has("m") {
            return Err(BuildError::missing(
                "m",
                "needs `m` (scalar modulus) or `T` (matrix)",
            ));
        }
        return Ok(Box::new(crate::Transformer::new(p.modulated("m")?)?));
    }
    if p.has("m") {
        return Err(BuildError::conflict(
            "m",
            "give either `m` (scalar) or `T` (matrix), not both",
        ));
    }
    let t = p.matrix("T")?;
    let (n1, n2, n_in) = (t.rows, t.cols, t.inputs.len());
    let specs = t.inputs.iter().map(|n| SignalSpec::scalar(n)).collect();
    let entries = t.entries;
    let law = Box::new(move |io: &Io<'_>, m: &mut nalgebra::DMatrix<f64>| {
        let mut u = [0.0; crate::element::MAX_PARAM_INPUTS];
        for (k, v) in u.iter_mut().take(n_in).enumerate() {
            *v = io.u(k);
        }
        for i in 0..n1 {
            for j in 0..n2 {
                m[(i, j)] = entries[i * n2 + j](&u[..n_in]);
            }
        }
    });
    Ok(Box::new(MatrixTransformer::new(n1, n2, specs, law)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;
    use crate::element::{Layout, PortLayout};

    #[test]
    fn apply_effort_and_flow_are_bit_identical_to_the_index_loops() {
        // the loops before the stack copies (through Io's accessors) are the reference;
        // shapes on both sides of the stack buffer's width (16)
        for (n1, n2) in [
            (1, 1),
            (9, 2),
            (9, 6),
            (2, 9),
            (16, 16),
            (17, 3),
            (3, 17),
            (20, 20),
        ] {
            let t = DMatrix::from_fn(n1, n2, |i, j| {
                ((i * 31 + j * 17) % 23) as f64 * 0.37 - 4.1 + 1e-3 * (i as f64 - j as f64)
            });
            let layout = Layout {
                ports: vec![
                    PortLayout {
                        offset: 1,
                        dim: n1,
                        sign: -1.0,
                        causality: PortCausality::EffortOut,
                    },
                    PortLayout {
                        offset: 2 + n1,
                        dim: n2,
                        sign: 1.0,
                        causality: PortCausality::FlowOut,
                    },
                ],
                ..Layout::default()
            };
            let len = 3 + n1 + n2;
            let fill = |k: usize, s: f64| (k as f64 * s).sin() * 10f64.powi((k % 7) as i32 - 3);
            let (e0, f0): (Vec<f64>, Vec<f64>) = (
                (0..len).map(|k| fill(k, 1.3)).collect(),
                (0..len).map(|k| fill(k, 0.7)).collect(),
            );
            let run = |fast: bool| {
                let (mut e, mut f, mut sig) = (e0.clone(), f0.clone(), Vec::new());
                let mut io = Io {
                    t: 0.0,
                    x: &[],
                    effort: &mut e,
                    flow: &mut f,
                    signals: &mut sig,
                    layout: &layout,
                };
                if fast {
                    apply_effort(&mut io, &t);
                    apply_flow(&mut io, &t);
                } else {
                    for i in 0..n1 {
                        let v: f64 = (0..n2).map(|j| t[(i, j)] * io.e(1, j)).sum();
                        io.set_e(0, i, v);
                    }
                    for j in 0..n2 {
                        let v: f64 = (0..n1).map(|i| t[(i, j)] * io.f_in(0, i)).sum();
                        io.set_f_in(1, j, -v);
                    }
                }
                e.iter().chain(&f).map(|v| v.to_bits()).collect::<Vec<_>>()
            };
            assert_eq!(run(true), run(false), "T {n1}×{n2}");
        }
    }

    #[test]
    fn partials_match_central_differences() {
        let t = DMatrix::from_row_slice(3, 2, &[1.0, -2.0, 0.5, 3.0, 0.0, 1.5]);
        let mtf = MatrixTransformer::constant(t).unwrap();
        let ports = [
            (3, 1.0, PortCausality::EffortOut),
            (2, -1.0, PortCausality::FlowOut),
        ];
        // e1[3], f1[3], e2[2], f2[2]
        let point: Vec<f64> = (0..10).map(|k| 0.7 * k as f64 - 2.0).collect();
        assert_eq!(check_partials(&mtf, &ports, &point), Ok(2));
        // a modulated modulus leaves the partials to the core
        let law: ModulusLaw = Box::new(|io, m| m.fill(io.u(0)));
        let mtf = MatrixTransformer::new(3, 2, vec![SignalSpec::scalar("u")], law).unwrap();
        let mut point = point;
        point.push(0.3);
        assert_eq!(check_partials(&mtf, &ports, &point), Ok(0));
    }
}
