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
        let max = self.modes.first().map_or(0.0, |m| m.eigenvalue.norm());
        self.modes
            .iter()
            .filter(move |m| m.eigenvalue.norm() > 1e-9 * max)
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
            "{:>3}  {:>12}  {:>12}  {:>9}  {:>11}  {:>24}  dominant states (participation)",
            "#", "f_n (Hz)", "f_d (Hz)", "ζ", "τ (s)", "λ (1/s)"
        );
        for (k, m) in self.modes.iter().enumerate() {
            let names = self
                .dominant(m, top)
                .iter()
                .map(|(n, p)| format!("{n} {p:.2}"))
                .collect::<Vec<_>>()
                .join(", ");
            let _ = writeln!(
                s,
                "{:>3}  {:>12.6}  {:>12.6}  {:>9.5}  {:>11.4e}  {:>24}  {names}",
                k + 1,
                m.natural_hz,
                m.damped_hz,
                m.damping_ratio,
                m.time_constant,
                format!("{:.4e} {:+.4e}i", m.eigenvalue.re, m.eigenvalue.im),
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
        let modes: Vec<String> = self
            .modes
            .iter()
            .map(|m| {
                let part: Vec<String> = self
                    .dominant(m, top)
                    .iter()
                    .map(|(n, p)| format!("{{\"state\": \"{}\", \"share\": {}}}", esc(n), num(*p)))
                    .collect();
                format!(
                    "{{\"re\": {}, \"im\": {}, \"natural_hz\": {}, \"damped_hz\": {}, \"damping_ratio\": {}, \"time_constant\": {}, \"participation\": [{}]}}",
                    num(m.eigenvalue.re),
                    num(m.eigenvalue.im),
                    num(m.natural_hz),
                    num(m.damped_hz),
                    num(m.damping_ratio),
                    num(m.time_constant),
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
