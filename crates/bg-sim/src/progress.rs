//! The progress bar of `bg-sim run`: simulated time, rate (simulated seconds per wall
//! second) and the time left, on stderr, only when stderr is a terminal and only once the
//! run has taken a second; at most ten updates a second. It reads the time of each output
//! row, and of each accepted step when the run computes the step values anyway (for the
//! checks); it adds no work to the run.

use std::time::{Duration, Instant};

use bondgraph::RowSink;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Nothing is drawn before the run has taken this long.
const AFTER: Duration = Duration::from_secs(1);
/// Least time between two updates.
const EVERY: Duration = Duration::from_millis(100);
/// Positions of the bar (per mille of the time span).
const STEPS: u64 = 1000;

/// A [`RowSink`] that passes every row on to `inner` and shows the progress.
pub struct Progress<'a> {
    inner: &'a mut dyn RowSink,
    show: bool,
    steps: bool,
    t0: f64,
    t_end: f64,
    started: Instant,
    last: Instant,
    bar: Option<ProgressBar>,
}

impl<'a> Progress<'a> {
    /// Rows go on to `inner`; `show`: draw at all (stderr is a terminal, not `--quiet`);
    /// `steps_free`: the run computes the values at every accepted step anyway (checks), so
    /// they may be read too.
    pub fn new(
        inner: &'a mut dyn RowSink,
        t0: f64,
        t_end: f64,
        show: bool,
        steps_free: bool,
    ) -> Self {
        let now = Instant::now();
        Self {
            inner,
            show,
            steps: steps_free,
            t0,
            t_end,
            started: now,
            last: now,
            bar: None,
        }
    }

    /// Whether a bar has been drawn.
    #[must_use]
    pub fn drawn(&self) -> bool {
        self.bar.is_some()
    }

    /// Remove the bar from the terminal.
    pub fn finish(&mut self) {
        if let Some(b) = self.bar.take() {
            b.finish_and_clear();
        }
    }

    fn tick(&mut self, t: f64) {
        if !self.show || !t.is_finite() {
            return;
        }
        let now = Instant::now();
        if now.duration_since(self.last) < EVERY || now.duration_since(self.started) < AFTER {
            return;
        }
        self.last = now;
        let span = self.t_end - self.t0;
        let done = if span > 0.0 {
            ((t - self.t0) / span).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let wall = now.duration_since(self.started).as_secs_f64();
        let rate = (t - self.t0) / wall;
        let left = if rate > 0.0 {
            format_secs((self.t_end - t).max(0.0) / rate)
        } else {
            "?".to_owned()
        };
        let bar = self.bar.get_or_insert_with(|| {
            let b =
                ProgressBar::with_draw_target(Some(STEPS), ProgressDrawTarget::stderr_with_hz(10));
            if let Ok(style) = ProgressStyle::with_template("{bar:30} {msg}") {
                b.set_style(style.progress_chars("=> "));
            }
            b
        });
        bar.set_position((done * STEPS as f64) as u64);
        bar.set_message(format!(
            "t = {t:.4} of {} s, {rate:.3} s/s, {left} left",
            self.t_end
        ));
    }
}

/// A duration for people: `42 s`, `3 min 05 s`, `1 h 02 min`.
fn format_secs(s: f64) -> String {
    if !s.is_finite() {
        return "?".to_owned();
    }
    let s = s.round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

impl RowSink for Progress<'_> {
    fn row(&mut self, row: &[f64]) -> Result<(), String> {
        self.tick(row.first().copied().unwrap_or(f64::NAN));
        self.inner.row(row)
    }
    fn wants_steps(&self) -> bool {
        (self.show && self.steps) || self.inner.wants_steps()
    }
    fn step(&mut self, values: &[f64]) {
        self.tick(values.first().copied().unwrap_or(f64::NAN));
        if self.inner.wants_steps() {
            self.inner.step(values);
        }
    }
    /// The bar reads `t` alone.
    fn step_reads(&self, column: usize) -> bool {
        self.inner.wants_steps() && self.inner.step_reads(column)
    }
}

impl Drop for Progress<'_> {
    fn drop(&mut self) {
        self.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_as_people_write_them() {
        assert_eq!(format_secs(4.4), "4 s");
        assert_eq!(format_secs(185.0), "3 min 05 s");
        assert_eq!(format_secs(3720.0), "1 h 02 min");
        assert_eq!(format_secs(f64::INFINITY), "?");
    }

    #[test]
    fn rows_pass_through_and_nothing_is_drawn_when_not_shown() {
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let mut p = Progress::new(&mut rows, 0.0, 1.0, false, true);
        assert!(!p.wants_steps());
        for i in 0..5 {
            p.row(&[f64::from(i) * 0.25, 1.0]).unwrap_or_default();
        }
        assert!(!p.drawn());
        drop(p);
        assert_eq!(rows.len(), 5);
    }
}
