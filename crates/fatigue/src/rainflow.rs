//! Rainflow counting of ASTM E1049-85 ("Standard Practices for Cycle Counting in Fatigue
//! Analysis"), §5.4.4, the three-point method: ranges are formed from the last three
//! turning points of a stack as the history is read.
//!
//! ```text
//! read the next reversal onto the stack; while it holds three or more points:
//!   X = |s[-1] − s[-2]| (the newest range), Y = |s[-2] − s[-3]| (the one before)
//!   X < Y: read on
//!   Y contains the starting point (the stack holds exactly three): count Y as ½ cycle,
//!     drop its first point (the starting point moves to Y's second point)       (step 5)
//!   otherwise: count Y as one cycle, drop both its points                        (step 4)
//! at the end, each range of the points left (the residue) is ½ cycle             (step 6)
//! ```
//!
//! **Residue.** [`Residue::Half`] is the standard's rule above. [`Residue::Repeat`] counts a
//! history that repeats without end (a duty cycle run `N` times a year): the starting point
//! never moves (no step 5), so the points left over form the residue; counting the residue
//! followed by itself closes it into full cycles, which are the cycles each further pass
//! adds. The result is then the cycles of one pass in a long periodic sequence — the same
//! as counting the history rotated to start and end at its largest peak.

/// One counted cycle: its range (peak − valley, ≥ 0), its mean ((peak + valley)/2), and
/// its count, 1 for a full cycle and 0.5 for a half cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cycle {
    /// Peak minus valley, in the history's unit (≥ 0).
    pub range: f64,
    /// Mean of peak and valley.
    pub mean: f64,
    /// 1.0 or 0.5 (more after [`merge`]).
    pub count: f64,
}

impl Cycle {
    fn of(a: f64, b: f64, count: f64) -> Self {
        Self {
            range: (a - b).abs(),
            mean: 0.5 * (a + b),
            count,
        }
    }

    /// The cycle with range and mean multiplied by `factor` (a unit, a gauge factor).
    #[must_use]
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            range: self.range * factor.abs(),
            mean: self.mean * factor,
            count: self.count,
        }
    }
}

/// What becomes of the points left over at the end of the history.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Residue {
    /// Each of their ranges counts as half a cycle (ASTM E1049-85 §5.4.4, step 6).
    Half,
    /// The history repeats: the residue is closed into full cycles (see the module notes).
    Repeat,
}

/// The turning points of `history`, with its first and last samples. With `gate = 0` a
/// point is a reversal where the slope changes sign (flat stretches are passed over). With
/// `gate > 0` (hysteresis): a peak or valley counts only once the history has moved back from
/// it by at least `gate`, so ranges smaller than the gate do not split a larger excursion;
/// the last point is then the extreme of the final excursion. Non-finite samples are the
/// caller's to refuse.
#[must_use]
pub fn reversals(history: &[f64], gate: f64) -> Vec<f64> {
    if gate > 0.0 {
        return gated(history, gate);
    }
    let mut out = Vec::new();
    let (Some(&first), Some(&second)) = (history.first(), history.get(1)) else {
        out.extend_from_slice(history);
        return out;
    };
    out.push(first);
    let (mut x, mut d_last) = (second, second - first);
    for &next in &history[2..] {
        #[allow(clippy::float_cmp)] // a flat stretch is exactly equal samples
        if next == x {
            continue;
        }
        let d = next - x;
        if d_last * d < 0.0 {
            out.push(x);
        }
        x = next;
        d_last = d;
    }
    out.push(x);
    out
}

/// [`reversals`] with a hysteresis gate > 0.
fn gated(history: &[f64], gate: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let Some(&first) = history.first() else {
        return out;
    };
    out.push(first);
    // direction of the current excursion (0: none yet) and its extreme so far
    let (mut dir, mut extreme) = (0.0_f64, first);
    for &x in &history[1..] {
        if dir == 0.0 {
            if (x - first).abs() >= gate {
                dir = (x - first).signum();
                extreme = x;
            }
        } else if (x - extreme) * dir > 0.0 {
            extreme = x;
        } else if (extreme - x) * dir >= gate {
            out.push(extreme);
            dir = -dir;
            extreme = x;
        }
    }
    if dir != 0.0 {
        out.push(extreme);
    }
    out
}

/// Rainflow count of the turning points `points` (from [`reversals`]), in the order the
/// cycles close; the residue per `residue`.
#[must_use]
pub fn count(points: &[f64], residue: Residue) -> Vec<Cycle> {
    match residue {
        Residue::Half => {
            let (mut cycles, left) = three_point(points, true);
            cycles.extend(left.windows(2).map(|w| Cycle::of(w[0], w[1], 0.5)));
            cycles
        }
        Residue::Repeat => {
            let (mut cycles, left) = three_point(points, false);
            let mut twice = left.clone();
            twice.extend_from_slice(&left);
            let (closing, _) = three_point(&reversals(&twice, 0.0), false);
            cycles.extend(closing);
            cycles
        }
    }
}

/// The stack algorithm; `halves`: with step 5 (half cycles at the starting point), else the
/// starting point stays and the residue keeps every point not closed. Returns the cycles
/// and the points left.
fn three_point(points: &[f64], halves: bool) -> (Vec<Cycle>, Vec<f64>) {
    let mut cycles = Vec::new();
    let mut s: Vec<f64> = Vec::with_capacity(points.len().min(1024));
    for &p in points {
        s.push(p);
        while s.len() >= 3 {
            let n = s.len();
            let x = (s[n - 1] - s[n - 2]).abs();
            let y = (s[n - 2] - s[n - 3]).abs();
            if x < y {
                break;
            }
            if n == 3 {
                if !halves {
                    break;
                }
                cycles.push(Cycle::of(s[0], s[1], 0.5));
                s.remove(0);
            } else {
                cycles.push(Cycle::of(s[n - 3], s[n - 2], 1.0));
                s.drain(n - 3..n - 1);
            }
        }
    }
    (cycles, s)
}

/// The cycles with equal range and mean merged (their counts added), largest range first
/// (then smallest mean): the table of a report.
#[must_use]
pub fn merge(cycles: &[Cycle]) -> Vec<Cycle> {
    let mut v = cycles.to_vec();
    v.sort_by(|a, b| {
        b.range
            .total_cmp(&a.range)
            .then_with(|| a.mean.total_cmp(&b.mean))
    });
    let mut out: Vec<Cycle> = Vec::with_capacity(v.len());
    for c in v {
        match out.last_mut() {
            Some(l)
                if l.range.to_bits() == c.range.to_bits()
                    && l.mean.to_bits() == c.mean.to_bits() =>
            {
                l.count += c.count;
            }
            _ => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The example of ASTM E1049-85 (its Fig. 6 and the rainflow table beside it).
    const ASTM: [f64; 9] = [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0];

    fn by_range(cycles: &[Cycle]) -> Vec<(f64, f64)> {
        let mut out: Vec<(f64, f64)> = Vec::new();
        for c in merge(cycles) {
            match out.last_mut() {
                Some(l) if (l.0 - c.range).abs() < 1e-12 => l.1 += c.count,
                _ => out.push((c.range, c.count)),
            }
        }
        out.reverse();
        out
    }

    #[test]
    fn the_astm_example_gives_the_published_counts() {
        let r = reversals(&ASTM, 0.0);
        assert_eq!(r, ASTM, "every sample of the example is a turning point");
        let cycles = count(&r, Residue::Half);
        // ASTM E1049-85, rainflow example: range 3: ½, 4: 1½, 6: ½, 8: 1, 9: ½
        assert_eq!(
            by_range(&cycles),
            [(3.0, 0.5), (4.0, 1.5), (6.0, 0.5), (8.0, 1.0), (9.0, 0.5)]
        );
        // the order the standard counts them in, with the means
        let want = [
            (3.0, -0.5, 0.5), // −2 → 1, step 5
            (4.0, -1.0, 0.5), // 1 → −3, step 5
            (4.0, 1.0, 1.0),  // −1 → 3, step 4
            (8.0, 1.0, 0.5),  // −3 → 5, step 5
            (9.0, 0.5, 0.5),  // 5 → −4, residue
            (8.0, 0.0, 0.5),  // −4 → 4
            (6.0, 1.0, 0.5),  // 4 → −2
        ];
        let got: Vec<(f64, f64, f64)> = cycles.iter().map(|c| (c.range, c.mean, c.count)).collect();
        assert_eq!(got, want);
    }

    #[test]
    fn reversals_skip_monotone_and_flat_stretches() {
        let h = [0.0, 1.0, 2.0, 2.0, 3.0, 1.0, 1.0, 0.5, 4.0, 4.0];
        assert_eq!(reversals(&h, 0.0), [0.0, 3.0, 0.5, 4.0]);
        assert_eq!(reversals(&[1.0], 0.0), [1.0]);
        assert!(reversals(&[], 0.0).is_empty());
    }

    #[test]
    fn the_gate_drops_small_wiggles_only() {
        let h = [0.0, 5.0, 4.8, 5.2, 4.9, 10.0, 0.0, 0.3, -0.1, 8.0];
        assert_eq!(reversals(&h, 0.0).len(), 10);
        assert_eq!(reversals(&h, 1.0), [0.0, 10.0, -0.1, 8.0]);
        // a gate larger than every range leaves only the first point
        assert_eq!(reversals(&[0.0, 1.0, 0.0], 5.0), [0.0]);
    }

    /// Deterministic pseudo-random history (xorshift).
    fn history(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    #[test]
    fn repeat_counts_the_cycles_each_further_pass_adds() {
        for seed in 1..20 {
            let h = history(200, seed);
            let per_pass = count(&reversals(&h, 0.0), Residue::Repeat);
            // independent of the residue rule: what the third pass adds to two, counted with
            // the standard's half cycles, is one pass of the periodic sequence
            let rep =
                |k: usize| -> Vec<f64> { h.iter().copied().cycle().take(k * h.len()).collect() };
            let total = |k: usize| -> f64 {
                count(&reversals(&rep(k), 0.0), Residue::Half)
                    .iter()
                    .map(|c| c.count * c.range.powi(3))
                    .sum()
            };
            let added = total(3) - total(2);
            let ours: f64 = per_pass.iter().map(|c| c.count * c.range.powi(3)).sum();
            assert!(
                (added - ours).abs() < 1e-12 * ours,
                "seed {seed}: {added} vs {ours}"
            );
            assert!(per_pass
                .iter()
                .all(|c| (c.count - 1.0).abs() < f64::EPSILON));
            // the rotation to the largest peak, closed there, counts the same full cycles
            let k = (0..h.len())
                .max_by(|&a, &b| h[a].total_cmp(&h[b]))
                .unwrap_or(0);
            let mut rot: Vec<f64> = h[k..].iter().chain(&h[..k]).copied().collect();
            rot.push(h[k]);
            let closed = count(&reversals(&rot, 0.0), Residue::Half);
            let closed: f64 = closed.iter().map(|c| c.count * c.range.powi(3)).sum();
            assert!((closed - ours).abs() < 1e-12 * ours, "seed {seed}");
        }
    }

    #[test]
    fn half_counts_every_range_once() {
        // every point enters one range: Σ count·(number of points it spans)… in effect the
        // total of half-cycle "legs" equals the number of reversals minus one
        for seed in 1..10 {
            let r = reversals(&history(500, seed), 0.0);
            let legs: f64 = count(&r, Residue::Half).iter().map(|c| 2.0 * c.count).sum();
            assert!((legs - (r.len() - 1) as f64).abs() < 1e-9);
        }
    }
}
