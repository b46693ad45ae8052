//! Palmgren–Miner damage: each counted cycle of range Δσ uses up 1/N(Δσ) of the life, and
//! the damage of a history is the sum D = Σ nᵢ / N(SCF·Δσᵢ); failure is predicted at D = 1.
//! The stress concentration factor SCF multiplies every range (a nominal stress to the hot
//! spot's).

use crate::{Cycle, SnCurve};

/// Miner's damage of `cycles` (ranges in Pa) on `curve`, every range multiplied by `scf`.
#[must_use]
pub fn damage(cycles: &[Cycle], curve: &SnCurve, scf: f64) -> f64 {
    cycles
        .iter()
        .map(|c| c.count / curve.cycles(scf * c.range))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{count, reversals, Residue};

    #[test]
    fn constant_amplitude_damage_is_n_over_n() {
        // n full cycles of range 2a: D = n / N(2a) from the formula N = 2e6 (Δσ_C/Δσ)³
        for (amp, scf) in [(50e6, 1.0), (40e6, 1.3), (30e6, 1.0)] {
            let n = 1000;
            let h: Vec<f64> = (0..=2 * n)
                .map(|k| if k % 2 == 0 { -amp } else { amp })
                .collect();
            let cycles = count(&reversals(&h, 0.0), Residue::Half);
            let curve = SnCurve::preset("ec3-71").unwrap();
            let range = 2.0 * amp * scf;
            let d_sigma_d = 71e6 * 0.4_f64.cbrt();
            let big_n = if range >= d_sigma_d {
                2e6 * (71e6 / range).powi(3)
            } else {
                5e6 * (d_sigma_d / range).powi(5)
            };
            let d = damage(&cycles, &curve, scf);
            let want = n as f64 / big_n;
            assert!(((d - want) / want).abs() < 1e-12, "{d} vs {want}");
        }
    }

    #[test]
    fn ranges_below_the_cut_off_do_no_damage() {
        let curve = SnCurve::preset("ec3-36").unwrap();
        let c = [Cycle {
            range: 10e6,
            mean: 0.0,
            count: 1e9,
        }];
        assert!(damage(&c, &curve, 1.0) < f64::MIN_POSITIVE);
    }
}
