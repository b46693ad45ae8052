//! The manipulator R-field: generalized damping forces `e = D f_in`, D = diag(d) ≥ 0.
//!
//! The scene's damping `D = diag(0, 0, r_p, r_e …)` acts on the joint speed of the
//! pendulum and on the modal speeds. Entries may be zero (resistance causality only, which
//! the arm's 1-junction gives it), so a scheduled event can switch them by rebuilding the
//! element with other values: the shape, causality and stages stay the same.

use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, Slot,
};

/// Diagonal generalized damping.
#[derive(Debug)]
pub struct ArmDamping {
    d: Vec<f64>,
}

impl ArmDamping {
    /// Damping coefficients `d` (one per generalized coordinate, each ≥ 0; N·s/m or
    /// N·m·s/rad).
    pub fn new(d: Vec<f64>) -> Result<Self, ParamError> {
        if d.is_empty() {
            return Err(ParamError::Shape {
                param: "damping".into(),
                message: "needs one value per generalized coordinate".into(),
            });
        }
        for &v in &d {
            ParamError::non_negative("damping", v)?;
        }
        Ok(Self { d })
    }
}

impl Element for ArmDamping {
    fn kind(&self) -> &str {
        "manipulator.r_field"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", self.d.len())])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::EffortOut]])
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        for (k, d) in self.d.iter().enumerate() {
            let e = d * io.f_in(0, k);
            io.set_e(0, k, e);
        }
    }
    fn stage_partials(&self, _: usize, _: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        for (k, d) in self.d.iter().enumerate() {
            jac.set(jac.row(Slot::Effort(0), k), jac.flow_col(0, k), *d);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_negative_damping() {
        assert!(ArmDamping::new(vec![0.0, -1.0]).is_err());
        assert!(ArmDamping::new(vec![]).is_err());
        assert!(ArmDamping::new(vec![0.0, 2.5e5]).is_ok());
    }
}
