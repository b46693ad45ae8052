//! The lumped cylinder masses (eq. 75): an I-field `ṗ = e`, `f_in = M_c⁻¹ p` with
//! `M_c = diag(m₁ I₂, m₂ I₂, …)`, velocities in frame 0 (x then y per mass).

use bondgraph::{
    CausalRule, Element, Io, ParamError, PortCausality, PortSpec, Ports, Stage, StateSpec,
};

use super::component_names;

/// Point masses moving in the plane.
#[derive(Debug)]
pub struct LumpedMasses {
    masses: Vec<f64>,
    p0: Vec<f64>,
}

impl LumpedMasses {
    /// Masses `masses` (kg, > 0) with initial velocities `v0` (x, y per mass; m/s).
    pub fn new(masses: Vec<f64>, v0: &[f64]) -> Result<Self, ParamError> {
        if masses.is_empty() || v0.len() != 2 * masses.len() {
            return Err(ParamError::Shape {
                param: "lumped_masses".into(),
                message: format!(
                    "{} masses need {} initial velocities, got {}",
                    masses.len(),
                    2 * masses.len(),
                    v0.len()
                ),
            });
        }
        for &m in &masses {
            ParamError::positive("lumped mass", m)?;
        }
        let p0 = v0
            .iter()
            .enumerate()
            .map(|(k, v)| masses[k / 2] * v)
            .collect();
        Ok(Self { masses, p0 })
    }
}

impl Element for LumpedMasses {
    fn kind(&self) -> &str {
        "manipulator.lumped_masses"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", self.p0.len())])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Integral(vec![PortCausality::FlowOut])
    }
    fn states(&self) -> Vec<StateSpec> {
        component_names("p", self.p0.len())
            .iter()
            .zip(&self.p0)
            .enumerate()
            .map(|(k, (n, &p))| StateSpec::new(n, p).nominal(self.masses[k / 2]))
            .collect()
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        Stage::from_states(causality, 0, 0)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        for k in 0..self.p0.len() {
            let v = io.states()[k] / self.masses[k / 2];
            io.set_f_in(0, k, v);
        }
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        for (k, d) in dx.iter_mut().enumerate() {
            *d = io.e(0, k);
        }
    }
    fn stored_energy(&self, x: &[f64]) -> Option<f64> {
        Some(
            x.iter()
                .enumerate()
                .map(|(k, p)| p * p / (2.0 * self.masses[k / 2]))
                .sum(),
        )
    }
}
