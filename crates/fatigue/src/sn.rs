//! S–N (Wöhler) curves of the Eurocode 3 / DNV shape: log-linear segments in log N against
//! log Δσ, with the intercepts log ā written as the standards do, for Δσ in MPa:
//!
//! ```text
//! log₁₀ N = log ā₁ − m₁ log₁₀ Δσ      for Δσ ≥ Δσ_knee
//! log₁₀ N = log ā₂ − m₂ log₁₀ Δσ      for Δσ_cut ≤ Δσ < Δσ_knee
//! N = ∞ (no damage)                    for Δσ < Δσ_cut (if the curve has a cut-off)
//! ```
//!
//! Ranges passed in and out of the API are in Pa (SI); only the intercepts are in MPa.
//!
//! **EN 1993-1-9** (Eurocode 3, fatigue; §7.1, Fig. 7.1, Tables 8.1–8.10) `ec3-<Δσ_C>`: the
//! detail category Δσ_C (MPa) is the range at N_C = 2·10⁶ on slope m₁ = 3; the constant
//! amplitude fatigue limit Δσ_D = (2/5)^(1/3) Δσ_C = 0.737 Δσ_C at 5·10⁶; slope m₂ = 5 from
//! there to the cut-off Δσ_L = (5/100)^(1/5) Δσ_D = 0.549 Δσ_D at 10⁸; no damage below it.
//!
//! **DNV-RP-C203** (DNV GL edition April 2016, Table 2-1, "S-N curves in air") `dnv-<curve>`:
//! log ā₁ and m₁ for N ≤ 10⁷, log ā₂ with m₂ = 5 for N > 10⁷, the knee (the fatigue limit
//! of the table) at 10⁷ cycles, no cut-off. (The 2024 edition moved B1–C2 to m₁ = 4 / 3.5
//! with a knee at 5·10⁶; these presets are the 2016 table.) The thickness correction of
//! the recommended practice (t/t_ref)^k is not applied: multiply it into `--scf`.

use std::fmt;

/// A named curve: its name in `--sn`, its source and how it is made.
#[derive(Clone, Copy, Debug)]
pub struct Preset {
    /// `ec3-71`, `dnv-d`, …
    pub name: &'static str,
    /// Where the numbers come from.
    pub source: &'static str,
    kind: PresetKind,
}

#[derive(Clone, Copy, Debug)]
enum PresetKind {
    /// EN 1993-1-9 detail category Δσ_C, MPa.
    Ec3(f64),
    /// DNV-RP-C203 (2016) Table 2-1: m₁, log ā₁, log ā₂ (m₂ = 5, knee at 10⁷).
    Dnv(f64, f64, f64),
}

const EC3: &str = "EN 1993-1-9, Fig. 7.1";
const DNV: &str = "DNVGL-RP-C203 (2016), Table 2-1";

/// Every preset, in the order of the docs' table.
pub const PRESETS: [Preset; 28] = [
    ec3("ec3-160", 160.0),
    ec3("ec3-140", 140.0),
    ec3("ec3-125", 125.0),
    ec3("ec3-112", 112.0),
    ec3("ec3-100", 100.0),
    ec3("ec3-90", 90.0),
    ec3("ec3-80", 80.0),
    ec3("ec3-71", 71.0),
    ec3("ec3-63", 63.0),
    ec3("ec3-56", 56.0),
    ec3("ec3-50", 50.0),
    ec3("ec3-45", 45.0),
    ec3("ec3-40", 40.0),
    ec3("ec3-36", 36.0),
    dnv("dnv-b1", 4.0, 15.117, 17.146),
    dnv("dnv-b2", 4.0, 14.885, 16.856),
    dnv("dnv-c", 3.0, 12.592, 16.320),
    dnv("dnv-c1", 3.0, 12.449, 16.081),
    dnv("dnv-c2", 3.0, 12.301, 15.835),
    dnv("dnv-d", 3.0, 12.164, 15.606),
    dnv("dnv-e", 3.0, 12.010, 15.350),
    dnv("dnv-f", 3.0, 11.855, 15.091),
    dnv("dnv-f1", 3.0, 11.699, 14.832),
    dnv("dnv-f3", 3.0, 11.546, 14.576),
    dnv("dnv-g", 3.0, 11.398, 14.330),
    dnv("dnv-w1", 3.0, 11.261, 14.101),
    dnv("dnv-w2", 3.0, 11.107, 13.845),
    dnv("dnv-w3", 3.0, 10.970, 13.617),
];

const fn ec3(name: &'static str, category: f64) -> Preset {
    Preset {
        name,
        source: EC3,
        kind: PresetKind::Ec3(category),
    }
}

const fn dnv(name: &'static str, m1: f64, log_a1: f64, log_a2: f64) -> Preset {
    Preset {
        name,
        source: DNV,
        kind: PresetKind::Dnv(m1, log_a1, log_a2),
    }
}

/// Pa per MPa: the standards' intercepts are for Δσ in MPa.
const MPA: f64 = 1e6;

/// An S–N curve (see the module notes). Ranges in Pa.
#[derive(Clone, Debug, PartialEq)]
pub struct SnCurve {
    /// How it was named (`ec3-71`, `m=3,range=71e6,cycles=2e6`).
    pub label: String,
    /// Slope of the first segment.
    pub m1: f64,
    /// log₁₀ ā₁ (Δσ in MPa).
    pub log_a1: f64,
    /// The second segment below the knee: (knee range in Pa, m₂, log₁₀ ā₂); `None`: one slope.
    pub knee: Option<(f64, f64, f64)>,
    /// Ranges below this (Pa) do no damage; `None`: every range does.
    pub cutoff: Option<f64>,
}

/// Why an `--sn` text is not a curve: a message and a hint.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SnError {
    /// What is wrong.
    pub message: String,
    /// How to write it.
    pub hint: String,
}

impl fmt::Display for SnError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}\n  hint: {}", self.message, self.hint)
    }
}

impl std::error::Error for SnError {}

impl SnCurve {
    /// The EN 1993-1-9 curve of detail category `category` (Δσ_C in MPa at 2·10⁶ cycles).
    #[must_use]
    pub fn eurocode(category: f64) -> Self {
        let c = category * MPA;
        let d = c * (2.0_f64 / 5.0).powf(1.0 / 3.0);
        let l = d * (5.0_f64 / 100.0).powf(1.0 / 5.0);
        let log_a = |n: f64, r: f64, m: f64| n.log10() + m * (r / MPA).log10();
        Self {
            label: format!("ec3-{category}"),
            m1: 3.0,
            log_a1: log_a(2e6, c, 3.0),
            knee: Some((d, 5.0, log_a(5e6, d, 5.0))),
            cutoff: Some(l),
        }
    }

    /// A DNV-RP-C203 in-air curve: log ā₁ with m₁ to the knee at 10⁷ cycles, log ā₂ with m₂ = 5 after it.
    #[must_use]
    pub fn dnv(label: &str, m1: f64, log_a1: f64, log_a2: f64) -> Self {
        let knee = 10f64.powf((log_a1 - 7.0) / m1) * MPA;
        Self {
            label: label.to_owned(),
            m1,
            log_a1,
            knee: Some((knee, 5.0, log_a2)),
            cutoff: None,
        }
    }

    /// The preset called `name` (case-insensitive), or `None`.
    #[must_use]
    pub fn preset(name: &str) -> Option<Self> {
        let p = PRESETS.iter().find(|p| p.name.eq_ignore_ascii_case(name))?;
        Some(match p.kind {
            PresetKind::Ec3(c) => Self::eurocode(c),
            PresetKind::Dnv(m1, a1, a2) => Self::dnv(p.name, m1, a1, a2),
        })
    }

    /// A preset name, or an explicit curve `m=3,range=71e6,cycles=2e6` (range in Pa at
    /// `cycles`), optionally with `knee=5e6` (cycles) and `m2=5` (the slope after it) and
    /// `cutoff=1e8` (cycles: no damage below the range there).
    pub fn parse(text: &str) -> Result<Self, SnError> {
        let text = text.trim();
        if !text.contains('=') {
            return Self::preset(text).ok_or_else(|| SnError {
                message: format!("unknown S–N curve `{text}`"),
                hint: format!(
                    "a preset ({}) or an explicit curve such as `m=3,range=71e6,cycles=2e6`",
                    PRESETS
                        .iter()
                        .map(|p| p.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
        let bad = |message: String| {
            SnError {
            message,
            hint: "write `m=3,range=71e6,cycles=2e6` (range in Pa at `cycles`), optionally `,knee=5e6,m2=5,cutoff=1e8`".into(),
        }
        };
        let mut keys = [None::<f64>; 6];
        const NAMES: [&str; 6] = ["m", "range", "cycles", "knee", "m2", "cutoff"];
        for part in text.split(',') {
            let (k, v) = part
                .split_once('=')
                .ok_or_else(|| bad(format!("`{part}` in `{text}` is not KEY=VALUE")))?;
            let (k, v) = (k.trim(), v.trim());
            let i = NAMES
                .iter()
                .position(|n| *n == k)
                .ok_or_else(|| bad(format!("unknown key `{k}` in `{text}`")))?;
            let x: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite() && *x > 0.0)
                .ok_or_else(|| bad(format!("`{k}={v}`: expected a finite number > 0")))?;
            if keys[i].replace(x).is_some() {
                return Err(bad(format!("`{k}` given twice in `{text}`")));
            }
        }
        let [Some(m), Some(range), Some(cycles), knee, m2, cutoff] = keys else {
            return Err(bad(format!("`{text}` lacks one of m, range, cycles")));
        };
        let log_a1 = cycles.log10() + m * (range / MPA).log10();
        let mut curve = Self {
            label: text.to_owned(),
            m1: m,
            log_a1,
            knee: None,
            cutoff: None,
        };
        match (knee, m2) {
            (Some(nk), Some(m2)) => {
                let rk = curve.range_at(nk);
                curve.knee = Some((rk, m2, nk.log10() + m2 * (rk / MPA).log10()));
            }
            (None, None) => {}
            _ => return Err(bad(format!("`{text}`: give `knee` and `m2` together"))),
        }
        if let Some(nc) = cutoff {
            curve.cutoff = Some(curve.range_at(nc));
        }
        Ok(curve)
    }

    /// Cycles to failure N at stress range `range` (Pa); infinite below the cut-off and
    /// for a zero range.
    #[must_use]
    pub fn cycles(&self, range: f64) -> f64 {
        if range <= 0.0 || self.cutoff.is_some_and(|c| range < c) {
            return f64::INFINITY;
        }
        let (m, log_a) = match self.knee {
            Some((rk, m2, a2)) if range < rk => (m2, a2),
            _ => (self.m1, self.log_a1),
        };
        10f64.powf(log_a - m * (range / MPA).log10())
    }

    /// The range (Pa) at which the curve gives `cycles` (the inverse of [`cycles`](Self::cycles)
    /// on the curve's segments, ignoring the cut-off).
    #[must_use]
    pub fn range_at(&self, cycles: f64) -> f64 {
        let on = |m: f64, a: f64| MPA * 10f64.powf((a - cycles.log10()) / m);
        match self.knee {
            Some((rk, m2, a2)) if cycles > self.cycles_on_first(rk) => on(m2, a2),
            _ => on(self.m1, self.log_a1),
        }
    }

    fn cycles_on_first(&self, range: f64) -> f64 {
        10f64.powf(self.log_a1 - self.m1 * (range / MPA).log10())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn eurocode_curves_pass_their_defining_points() {
        for c in [36.0, 71.0, 160.0] {
            let s = SnCurve::eurocode(c);
            let (cc, d, l) = (
                c * 1e6,
                c * 1e6 * 0.4_f64.cbrt(),
                c * 1e6 * 0.4_f64.cbrt() * 0.05_f64.powf(0.2),
            );
            assert!(rel(s.cycles(cc), 2e6) < 1e-12);
            assert!(rel(s.cycles(d * (1.0 + 1e-12)), 5e6) < 1e-9); // the knee, from above
            assert!(rel(s.cycles(d * (1.0 - 1e-12)), 5e6) < 1e-9); // and below: continuous
            assert!(rel(s.cycles(l * (1.0 + 1e-12)), 1e8) < 1e-9); // the cut-off
            assert!(s.cycles(l * (1.0 - 1e-9)).is_infinite());
            // the factors the standard prints: Δσ_D = 0.737 Δσ_C, Δσ_L = 0.549 Δσ_D
            assert!((d / cc - 0.737).abs() < 5e-4 && (l / d - 0.549).abs() < 5e-4);
            // slope 3, then 5
            assert!(rel(s.cycles(2.0 * cc), 2e6 / 8.0) < 1e-12);
            assert!(
                rel(
                    s.cycles(0.9 * d) / s.cycles(0.95 * d),
                    (0.95_f64 / 0.9).powi(5)
                ) < 1e-12
            );
        }
    }

    #[test]
    fn dnv_table_is_consistent_at_its_knee() {
        // Table 2-1 prints the fatigue limit at 10⁷ cycles beside log ā₁ and log ā₂: both
        // segments must give it (to the table's rounding of three decimals in log ā)
        let limits = [
            ("dnv-b1", 106.97),
            ("dnv-b2", 93.59),
            ("dnv-c", 73.10),
            ("dnv-c1", 65.50),
            ("dnv-c2", 58.48),
            ("dnv-d", 52.63),
            ("dnv-e", 46.78),
            ("dnv-f", 41.52),
            ("dnv-f1", 36.84),
            ("dnv-f3", 32.75),
            ("dnv-g", 29.24),
            ("dnv-w1", 26.32),
            ("dnv-w2", 23.39),
            ("dnv-w3", 21.05),
        ];
        for (name, fl) in limits {
            let s = SnCurve::preset(name).unwrap();
            let (rk, m2, a2) = s.knee.unwrap();
            // log ā to three decimals is ±0.0005 in log N, ±0.0005/m₁ in log Δσ: 4e-4 at most
            assert!(rel(rk, fl * 1e6) < 5e-4, "{name}: knee {rk} vs {fl} MPa");
            let n2 = 10f64.powf(a2 - m2 * fl.log10());
            assert!(
                rel(n2, 1e7) < 1e-2,
                "{name}: second segment at the limit gives {n2}"
            );
        }
        // D curve by hand: log N = 12.164 − 3 log 100 at 100 MPa → N = 1.4588e6
        let d = SnCurve::preset("DNV-D").unwrap();
        assert!(rel(d.cycles(100e6), 10f64.powf(6.164)) < 1e-12);
    }

    #[test]
    fn explicit_curves_parse_and_bad_ones_say_how() {
        let s = SnCurve::parse("m=3,range=71e6,cycles=2e6").unwrap();
        assert!(rel(s.cycles(71e6), 2e6) < 1e-12);
        assert!(rel(s.cycles(35.5e6), 16e6) < 1e-12);
        assert!(s.knee.is_none() && s.cutoff.is_none());
        // the explicit form of ec3-71 is ec3-71
        let e = SnCurve::parse("m=3, range=71e6, cycles=2e6, knee=5e6, m2=5, cutoff=1e8").unwrap();
        let p = SnCurve::preset("ec3-71").unwrap();
        for r in [20e6, 40e6, 50e6, 60e6, 100e6, 300e6] {
            let (a, b) = (e.cycles(r), p.cycles(r));
            assert!(
                a.to_bits() == b.to_bits() || rel(a, b) < 1e-12,
                "{r}: {a} vs {b}"
            );
        }
        for bad in [
            "ec3-70",
            "m=3,range=71e6",
            "m=3,range=-1,cycles=2e6",
            "m=3,range=71e6,cycles=2e6,knee=5e6",
            "q=1,m=3,range=1,cycles=1",
        ] {
            let e = SnCurve::parse(bad).unwrap_err();
            assert!(!e.hint.is_empty(), "{bad}");
        }
        let e = SnCurve::parse("ec3-70").unwrap_err();
        assert!(
            e.hint.contains("ec3-71") && e.hint.contains("dnv-w3"),
            "{}",
            e.hint
        );
    }
}
