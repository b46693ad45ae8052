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

/// The modulus law: fill `t` (n₁×n₂) from time and the element's inputs.
pub type ModulusLaw = Box<dyn Fn(&Io<'_>, &mut DMatrix<f64>)>;

/// `e₁ = T·e₂` on ports 0 and 1 of `io` (for matrix MTFs of other crates too).
pub fn apply_effort(io: &mut Io<'_>, t: &DMatrix<f64>) {
    for i in 0..t.nrows() {
        let e: f64 = (0..t.ncols()).map(|j| t[(i, j)] * io.e(1, j)).sum();
        io.set_e(0, i, e);
    }
}

/// `f_in₂ = −Tᵀ·f_in₁` on ports 0 and 1 of `io`.
pub fn apply_flow(io: &mut Io<'_>, t: &DMatrix<f64>) {
    for j in 0..t.ncols() {
        let f: f64 = (0..t.nrows()).map(|i| t[(i, j)] * io.f_in(0, i)).sum();
        io.set_f_in(1, j, -f);
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
}
