//! `bg-sim stress --fatigue CURVE`: each link's hot-spot history (σ at the section and outer
//! fibre of the hot spot, at the output rows) rainflow-counted (ASTM E1049-85, `bg_fatigue`)
//! and its Palmgren–Miner damage on the S–N curve, exactly as `bg-sim fatigue --sn CURVE`
//! counts that history written to a CSV (SCF 1, no gate; the residue as half cycles, or
//! closed by repeating the run with `--repeat-per-year`).

use bg_fatigue::rainflow::merge;
use bg_fatigue::{count, damage, reversals, Cycle, Residue, SnCurve};
use serde_json::{json, Value};

/// The fatigue of one hot spot.
pub(super) struct HotFatigue {
    /// The curve's label (`ec3-71`, or the explicit text).
    pub curve: String,
    /// `top` or `bottom`: the fibre of the hot spot.
    pub fibre: &'static str,
    /// The counted cycles, equal range and mean merged, largest range first.
    pub cycles: Vec<Cycle>,
    /// Miner's damage of one run.
    pub damage: f64,
    /// The runs a year, if given.
    pub per_year: Option<f64>,
}

impl HotFatigue {
    /// Count `history` (σ in Pa at the output rows) on `curve`.
    pub fn of(history: &[f64], column: &str, curve: &SnCurve, per_year: Option<f64>) -> Self {
        let residue = if per_year.is_some() {
            Residue::Repeat
        } else {
            Residue::Half
        };
        let cycles = count(&reversals(history, 0.0), residue);
        Self {
            curve: curve.label.clone(),
            fibre: if column.contains("sigma_top") {
                "top"
            } else {
                "bottom"
            },
            damage: damage(&cycles, curve, 1.0),
            cycles: merge(&cycles),
            per_year,
        }
    }

    /// 1/damage: the runs to failure (`None`: no damage).
    pub fn life(&self) -> Option<f64> {
        (self.damage > 0.0).then(|| 1.0 / self.damage)
    }

    /// The JSON object under `hot_spot.fatigue`: `curve`, `damage`, `life_repeats`, `cycles`
    /// (as `bg-sim fatigue --format json`), and `fibre`, and `life_years` with a yearly count.
    pub fn json(&self) -> Value {
        let cycles: Vec<Value> = self
            .cycles
            .iter()
            .map(|c| json!({"range": c.range, "mean": c.mean, "count": c.count}))
            .collect();
        let mut o = json!({"curve": self.curve, "damage": self.damage,
            "life_repeats": self.life(), "cycles": cycles, "fibre": self.fibre});
        if let Some(n) = self.per_year {
            o["life_years"] = json!(self.life().map(|l| l / n));
        }
        o
    }

    /// One line of the text report.
    pub fn text(&self) -> String {
        let n: f64 = self.cycles.iter().map(|c| c.count).sum();
        let largest = self.cycles.first().map_or(0.0, |c| c.range);
        let mut s = format!(
            "  fatigue ({}, {} fibre): {n} cycles, largest range {:.1} MPa, damage {:.4e} per run, life ",
            self.curve,
            self.fibre,
            largest * 1e-6,
            self.damage
        );
        match (self.life(), self.per_year) {
            (None, _) => s.push_str("unlimited (every range below the cut-off)"),
            (Some(l), None) => s.push_str(&format!("{l:.0} runs")),
            (Some(l), Some(y)) => {
                s.push_str(&format!(
                    "{l:.0} runs, {:.2} years at {y} runs a year",
                    l / y
                ));
            }
        }
        s
    }
}
