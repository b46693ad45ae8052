//! Gravity on the lumped cylinder masses (eq. 76): an effort source
//! `e = −g [0 m₁ 0 m₂ …]ᵀ` (frame 0, x then y per mass).

use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, ParamError, PortCausality, PortSpec, Ports, Stage,
};

/// The weights of point masses, as a multiport effort source.
#[derive(Debug)]
pub struct LumpedGravity {
    masses: Vec<f64>,
    g: f64,
}

impl LumpedGravity {
    /// Weights of `masses` (kg) under gravity `g` (m/s², along −y₀).
    pub fn new(masses: Vec<f64>, g: f64) -> Result<Self, ParamError> {
        if masses.is_empty() {
            return Err(ParamError::Shape {
                param: "lumped_masses".into(),
                message: "needs at least one mass".into(),
            });
        }
        ParamError::finite("gravity", g)?;
        Ok(Self { masses, g })
    }
}

impl Element for LumpedGravity {
    fn kind(&self) -> &str {
        "manipulator.lumped_gravity"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", 2 * self.masses.len())])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Fixed(vec![PortCausality::EffortOut])
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        Stage::from_states(causality, 0, 0)
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        for (k, m) in self.masses.iter().enumerate() {
            io.set_e(0, 2 * k, 0.0);
            io.set_e(0, 2 * k + 1, -m * self.g);
        }
    }
    fn stage_partials(&self, _: usize, _: &Io<'_>, _: &mut LocalJacobian<'_>) -> bool {
        true // constant weights
    }
}
