//! The lumped cylinder masses (eq. 75): an I-field `ṗ = e`, `f_in = M_c⁻¹ p` with
//! `M_c = diag(m₁ I₂, m₂ I₂, …)`, velocities in frame 0 (x then y per mass). It is the core
//! [`Inertia`] with one mass per component.

use bondgraph::{Inertia, ParamError};

/// The lumped masses `masses` (kg, > 0), moving in the plane with initial velocities `v0`
/// (x, y per mass; m/s): an [`Inertia`] on a 2m-bond.
pub fn lumped_masses(masses: &[f64], v0: &[f64]) -> Result<Inertia, ParamError> {
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
    let diagonal: Vec<f64> = masses.iter().flat_map(|&m| [m, m]).collect();
    let p0 = v0.iter().zip(&diagonal).map(|(v, m)| m * v).collect();
    Inertia::diagonal(diagonal, p0).map_err(|e| match e {
        ParamError::OutOfRange {
            value, requirement, ..
        } => ParamError::OutOfRange {
            param: "lumped mass".into(),
            value,
            requirement,
        },
        other => other,
    })
}

#[cfg(test)]
mod tests {
    use bondgraph::Element;

    use super::*;

    #[test]
    fn one_mass_per_pair_of_components() {
        let m = lumped_masses(&[2.0, 4.0], &[1.0, 0.0, 0.0, 0.5]).unwrap();
        let p0: Vec<f64> = m.states().iter().map(|s| s.initial).collect();
        assert_eq!(p0, [2.0, 0.0, 0.0, 2.0]);
        assert_eq!(m.stored_energy(&p0), Some(1.0 + 0.5));
        assert!(lumped_masses(&[1.0], &[0.0]).is_err());
        assert!(lumped_masses(&[-1.0], &[0.0, 0.0]).is_err());
    }
}
