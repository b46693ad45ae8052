//! `bg-sim modes`: the model's time scales. Linearise at the initial state or at time T of a
//! run, list every eigenvalue ([`bondgraph::modes()`]) with the states that take part in it,
//! and say what they mean for the choice of solver. No physics lives here.

use std::fmt::Write as _;

use bg_model::Model;
use bondgraph::{stiffness_ratio, Mode};

/// The modes of a model at one state.
#[derive(Debug)]
pub struct ModesReport {
    /// Model title or file.
    pub model: String,
    /// Time of the linearisation (s).
    pub t: f64,
    /// The run's length (t_end − t_start of the model's settings), s.
    pub span: f64,
    /// State names, in state order.
    pub states: Vec<String>,
    /// The modes, fastest first (complex pairs once).
    pub modes: Vec<Mode>,
    /// max|λ| / min|λ| over the non-zero eigenvalues.
    pub stiffness_ratio: f64,
    /// Eigenvalues below 1e-9 of the largest (integrators, rigid-body motion).
    pub zero_modes: usize,
}

/// A row sink that keeps nothing.
struct Discard;

impl bondgraph::RowSink for Discard {
    fn row(&mut self, _row: &[f64]) -> Result<(), String> {
        Ok(())
    }
}

/// Linearise `model` at its initial state (`at` = None or t_start) or at time `at` of a run
/// (the events up to `at` applied).
pub fn analyse(model: &mut Model, at: Option<f64>) -> Result<ModesReport, String> {
    let span = model.settings.t_end - model.settings.t_start;
    let (t, x) = match at {
        Some(t_at) if t_at > model.settings.t_start => {
            model.settings.t_end = t_at;
            // only the final state is wanted: the rows are dropped as they come
            let (out, _) = model.run_into(&mut Discard).map_err(|e| e.to_string())?;
            if let Some(e) = &out.error {
                return Err(format!("the run to t = {t_at} s stopped early: {e}"));
            }
            // the elements as the events left them at t_at
            for ev in model.events().map_err(|e| e.to_string())? {
                if ev.t <= t_at {
                    for (id, el) in ev.replacements {
                        model.equations.replace(id, el).map_err(|e| e.to_string())?;
                    }
                }
            }
            (out.t_final, out.x_final)
        }
        Some(t_at) if t_at < model.settings.t_start => {
            return Err(format!(
                "--at {t_at} is before t_start = {} s",
                model.settings.t_start
            ))
        }
        _ => {
            // events at t_start apply before the first step
            for ev in model.events().map_err(|e| e.to_string())? {
                if ev.t <= model.settings.t_start {
                    for (id, el) in ev.replacements {
                        model.equations.replace(id, el).map_err(|e| e.to_string())?;
                    }
                }
            }
            (model.settings.t_start, model.x0.clone())
        }
    };
    let modes = bondgraph::modes(&model.equations, t, &x).map_err(|e| e.to_string())?;
    let (ratio, zeros) = stiffness_ratio(&modes);
    Ok(ModesReport {
        model: model
            .title
            .clone()
            .unwrap_or_else(|| model.file().to_owned()),
        t,
        span,
        states: model
            .equations
            .states()
            .iter()
            .map(|s| s.name.clone())
            .collect(),
        modes,
        stiffness_ratio: ratio,
        zero_modes: zeros,
    })
}

/// A mode with |λ| at most this fraction of the largest |λ| is neutral: a rigid-body
/// motion or an integrator (λ = 0 but for rounding: +6.5e-7 1/s beside 1e4 1/s is no
/// instability). It is reported as neutral, with no damping ratio or time constant, and
/// counted apart from the stiffness ratio (issue 24, item 4).
pub const NEUTRAL: f64 = 1e-9;

/// Damping ratio below which BDF of order 3, 4, 5 is not stable for a mode at large h·|λ|:
/// cos of the stability angles α = 86.03°, 73.35°, 51.84° (Hairer & Wanner, Table V.2.3).
const BDF_ZETA: [(usize, f64); 3] = [(3, 0.0692), (4, 0.2866), (5, 0.6180)];

impl ModesReport {
    /// The states that take part in mode `m` with a share ≥ 5 %, at most `top`.
    fn dominant(&self, m: &Mode, top: usize) -> Vec<(String, f64)> {
        m.participation
            .iter()
            .filter(|(_, s)| *s >= 0.05)
            .take(top)
            .map(|&(i, s)| (self.states[i].clone(), s))
            .collect()
    }

    fn nonzero(&self) -> impl Iterator<Item = &Mode> {
        self.modes.iter().filter(move |m| !self.is_neutral(m))
    }

    /// Whether `m` is neutral: |λ| ≤ [`NEUTRAL`]·max|λ| (a model whose every |λ| is 0 has
    /// only neutral modes).
    #[must_use]
    pub fn is_neutral(&self, m: &Mode) -> bool {
        let max = self
            .modes
            .iter()
            .map(|m| m.eigenvalue.norm())
            .fold(0.0, f64::max);
        m.eigenvalue.norm() <= NEUTRAL * max
    }

    /// One label per mode, distinct: its dominant state, or, where an earlier mode took it
    /// (two equal lags share both states), its most participating state not yet taken;
    /// `STATE #k` if every state of it is taken.
    #[must_use]
    pub fn labels(&self) -> Vec<String> {
        let mut taken: Vec<String> = Vec::new();
        for m in &self.modes {
            let free = m
                .participation
                .iter()
                .map(|&(i, _)| self.states[i].clone())
                .find(|n| !taken.contains(n));
            let label = free.unwrap_or_else(|| {
                let first = m
                    .participation
                    .first()
                    .map_or_else(|| "?".to_owned(), |&(i, _)| self.states[i].clone());
                let k = (2..)
                    .find(|k| !taken.contains(&format!("{first} #{k}")))
                    .unwrap_or(2);
                format!("{first} #{k}")
            });
            taken.push(label);
        }
        taken
    }

    /// What the time scales mean for the choice of solver, one sentence a line.
    #[must_use]
    pub fn advice(&self) -> Vec<String> {
        let mut out = Vec::new();
        let Some(fast) = self.modes.first() else {
            return out;
        };
        let lmax = fast.eigenvalue.norm();
        if lmax <= 0.0 {
            return out;
        }
        let h_explicit = 2.8 / lmax;
        out.push(format!(
            "fastest mode |λ| = {lmax:.4e} 1/s ({:.4} Hz, ζ = {:.3}): an explicit method (tsit45) is stable only for h ≲ 2.8/|λ| = {h_explicit:.2e} s, about {:.0} steps for the {} s run, whatever the tolerance",
            fast.natural_hz, fast.damping_ratio, self.span / h_explicit, self.span
        ));
        let light: Vec<&Mode> = self
            .nonzero()
            .filter(|m| m.damping_ratio < 0.05 && m.damped_hz > 0.0)
            .collect();
        if let Some(top) = light.first() {
            let worst = BDF_ZETA
                .iter()
                .filter(|(_, z)| light.iter().any(|m| m.damping_ratio < *z))
                .map(|(k, _)| k.to_string())
                .collect::<Vec<_>>();
            out.push(format!(
                "{} lightly damped oscillating modes (ζ < 0.05), up to {:.4} Hz: an A-stable method is needed for steps longer than their periods; BDF of order {} is not stable for them at large h·|λ| (its order or step is cut); radau5 (L-stable) and esdirk34 are",
                light.len(),
                top.natural_hz,
                if worst.is_empty() { "3–5".into() } else { worst.join(", ") }
            ));
        }
        if let Some(slow) = self
            .nonzero()
            .filter(|m| m.damped_hz > 0.0 && m.damping_ratio < 0.2)
            .min_by(|a, b| a.damped_hz.total_cmp(&b.damped_hz))
        {
            let tau = slow.time_constant;
            out.push(format!(
                "slowest lightly damped oscillation: period {:.4} s (ζ = {:.4}, τ = {tau:.4} s, led by {}); it decays over 5τ = {:.4} s{}: any method needs steps of a fraction of its period for the whole run",
                1.0 / slow.damped_hz,
                slow.damping_ratio,
                self.dominant(slow, 1).first().map_or("?", |d| d.0.as_str()),
                5.0 * tau,
                if 5.0 * tau > self.span { format!(", longer than the {} s run", self.span) } else { String::new() }
            ));
        }
        let frozen = self
            .nonzero()
            .filter(|m| m.time_constant > 100.0 * self.span && m.damped_hz < 1.0 / self.span)
            .count();
        if frozen > 0 {
            out.push(format!(
                "{frozen} modes are slower than 100 runs (τ > {:.3e} s: leakage, integrators): over the run they are constants and limit no solver",
                100.0 * self.span
            ));
        }
        let growing = self
            .nonzero()
            .filter(|m| m.eigenvalue.re > 1e-9 * lmax)
            .count();
        if growing > 0 {
            out.push(format!(
                "{growing} modes grow (Re λ > 0): the linearisation is unstable here"
            ));
        }
        out.push(format!(
            "stiffness ratio max|λ|/min|λ| = {:.3e} over the non-zero eigenvalues ({} near-zero: integrators, rigid-body motion); max|λ|·(run length) = {:.3e}: the fastest time scale fits that many times into the run, which is what makes the model stiff for it",
            self.stiffness_ratio, self.zero_modes, lmax * self.span
        ));
        out
    }

    /// The report as text: one line per mode, then the advice.
    #[must_use]
    pub fn text(&self, top: usize) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{}: {} states, linearised at t = {} s; {} modes (complex pairs once), fastest first",
            self.model,
            self.states.len(),
            self.t,
            self.modes.len()
        );
        let _ = writeln!(
            s,
            "{:>3}  {:>12}  {:>12}  {:>9}  {:>11}  {:>24}  mode: dominant states (participation)",
            "#", "f_n (Hz)", "f_d (Hz)", "ζ", "τ (s)", "λ (1/s)"
        );
        let labels = self.labels();
        for (k, m) in self.modes.iter().enumerate() {
            let names = self
                .dominant(m, top)
                .iter()
                .map(|(n, p)| format!("{n} {p:.2}"))
                .collect::<Vec<_>>()
                .join(", ");
            let lambda = format!("{:.4e} {:+.4e}i", m.eigenvalue.re, m.eigenvalue.im);
            if self.is_neutral(m) {
                let _ = writeln!(
                    s,
                    "{:>3}  {:>12.6}  {:>12.6}  {:>9}  {:>11}  {lambda:>24}  {}: neutral (rigid-body or integrator; |λ| ≤ {NEUTRAL:e}·max|λ|): {names}",
                    k + 1,
                    m.natural_hz,
                    m.damped_hz,
                    "neutral",
                    "—",
                    labels[k],
                );
                continue;
            }
            let _ = writeln!(
                s,
                "{:>3}  {:>12.6}  {:>12.6}  {:>9.5}  {:>11.4e}  {lambda:>24}  {}: {names}",
                k + 1,
                m.natural_hz,
                m.damped_hz,
                m.damping_ratio,
                m.time_constant,
                labels[k],
            );
        }
        for a in self.advice() {
            let _ = writeln!(s, "- {a}");
        }
        s
    }

    /// The report as JSON.
    #[must_use]
    pub fn json(&self, top: usize) -> String {
        let num = |v: f64| {
            if v.is_finite() {
                format!("{v:e}")
            } else {
                "null".into()
            }
        };
        let esc = |t: &str| t.replace('\\', "\\\\").replace('"', "\\\"");
        let labels = self.labels();
        let modes: Vec<String> = self
            .modes
            .iter()
            .zip(&labels)
            .map(|(m, label)| {
                let neutral = self.is_neutral(m);
                let part: Vec<String> = self
                    .dominant(m, top)
                    .iter()
                    .map(|(n, p)| format!("{{\"state\": \"{}\", \"share\": {}}}", esc(n), num(*p)))
                    .collect();
                format!(
                    "{{\"label\": \"{}\", \"neutral\": {neutral}, \"re\": {}, \"im\": {}, \"natural_hz\": {}, \"damped_hz\": {}, \"damping_ratio\": {}, \"time_constant\": {}, \"participation\": [{}]}}",
                    esc(label),
                    num(m.eigenvalue.re),
                    num(m.eigenvalue.im),
                    num(m.natural_hz),
                    num(m.damped_hz),
                    if neutral { "null".into() } else { num(m.damping_ratio) },
                    if neutral { "null".into() } else { num(m.time_constant) },
                    part.join(", ")
                )
            })
            .collect();
        let advice: Vec<String> = self
            .advice()
            .iter()
            .map(|a| format!("\"{}\"", esc(a)))
            .collect();
        format!(
            "{{\"model\": \"{}\", \"t\": {}, \"n_states\": {}, \"stiffness_ratio\": {}, \"zero_modes\": {}, \"modes\": [\n  {}\n], \"advice\": [{}]}}",
            esc(&self.model),
            num(self.t),
            self.states.len(),
            num(self.stiffness_ratio),
            self.zero_modes,
            modes.join(",\n  "),
            advice.join(", ")
        )
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A real mode λ = `re`, as `bondgraph::modes` states it.
    fn mode(re: f64, participation: Vec<(usize, f64)>) -> Mode {
        let norm = re.abs();
        Mode {
            eigenvalue: re.into(),
            natural_hz: norm / std::f64::consts::TAU,
            damped_hz: 0.0,
            damping_ratio: if norm > 0.0 { -re / norm } else { 0.0 },
            time_constant: if re < 0.0 { -1.0 / re } else { f64::INFINITY },
            participation,
        }
    }

    /// Issue 24, item 4: two equal lags (a repeated eigenvalue whose eigenvectors both lean
    /// on spool2.y) get distinct labels; a near-zero eigenvalue of +6.5e-7 beside −1e4 is
    /// neutral, not an unstable mode with ζ = −1; the advice counts it apart.
    #[test]
    fn equal_lags_get_distinct_labels_and_a_near_zero_eigenvalue_is_neutral() {
        let report = ModesReport {
            model: "excavator".into(),
            t: 0.0,
            span: 10.0,
            states: vec!["spool1.y".into(), "spool2.y".into(), "piston.x".into()],
            modes: vec![
                mode(-1e4, vec![(1, 0.6), (0, 0.4)]),
                mode(-1e4, vec![(1, 0.55), (0, 0.45)]),
                mode(6.5e-7, vec![(2, 1.0)]),
            ],
            stiffness_ratio: 1.0,
            zero_modes: 1,
        };
        assert_eq!(report.labels(), ["spool2.y", "spool1.y", "piston.x"]);
        let text = report.text(3);
        assert!(!text.contains("-1.00000"), "{text}");
        assert!(
            text.contains("piston.x: neutral (rigid-body or integrator"),
            "{text}"
        );
        assert!(!text.contains("grow"), "{text}");
        let json = report.json(3);
        assert!(json.contains("\"label\": \"spool1.y\""), "{json}");
        assert!(json.contains("\"neutral\": true"), "{json}");
        assert!(json.contains("\"damping_ratio\": null"), "{json}");
        // every state taken: numbered
        let mut more = report;
        more.modes.push(mode(-5.0, vec![(2, 1.0)]));
        assert_eq!(more.labels()[3], "piston.x #2");
    }
}
