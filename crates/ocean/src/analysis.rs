//! Checks of a sampled record: its standard deviation, a Welch estimate of its spectrum and
//! the spectral peak period. Used by the tests and by `bg-sim sea --plot`.
//!
//! The spectrum estimate is Welch's: segments of 2ᵖ samples (the power of two nearest to
//! 256 s of record, at most the record), overlapping by half, each with its mean removed
//! and a Hann window, a radix-2 FFT; the one-sided density in m²·s/rad is
//! S(ωⱼ) = 2·dt·|Xⱼ|² / (2π·Σw²), averaged over the segments, so that ∫S dω is the
//! variance. The peak period is 2π/ω_p with ω_p the largest value of the estimate
//! smoothed by a five-bin running mean, refined by a
//! parabola through the logarithms of it and its two neighbours (the resolution is
//! 2π/256 s ≈ 0.025 rad/s, 3.5 % of ωp at Tp = 9 s; the parabola removes the grid's bias).

use std::f64::consts::PI;

/// The standard deviation of `x` (population: divided by n).
#[must_use]
pub fn std(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt()
}

/// In-place radix-2 FFT of (re, im); the length must be a power of two.
fn fft(re: &mut [f64], im: &mut [f64]) {
    let n = re.len();
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let ang = -2.0 * PI / len as f64;
        for start in (0..n).step_by(len) {
            for k in 0..len / 2 {
                let (s, c) = (ang * k as f64).sin_cos();
                let (a, b) = (start + k, start + k + len / 2);
                let tr = re[b] * c - im[b] * s;
                let ti = re[b] * s + im[b] * c;
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
            }
        }
        len <<= 1;
    }
}

/// Welch's estimate of the one-sided spectrum of `x` sampled every `dt` s: (ω [rad/s],
/// S [unit²·s/rad]) from ω = 0 to the Nyquist frequency (see the module documentation).
/// Empty for fewer than 16 samples.
#[must_use]
pub fn welch(x: &[f64], dt: f64) -> (Vec<f64>, Vec<f64>) {
    if x.len() < 16 {
        return (Vec::new(), Vec::new());
    }
    let want = (256.0 / dt).max(16.0);
    let mut len = 16usize;
    while len * 2 <= x.len() && (len * 2) as f64 <= want * 1.5 {
        len *= 2;
    }
    let window: Vec<f64> = (0..len)
        .map(|k| 0.5 - 0.5 * (2.0 * PI * k as f64 / len as f64).cos())
        .collect();
    let w2: f64 = window.iter().map(|w| w * w).sum();
    let half = len / 2;
    let mut s = vec![0.0; half + 1];
    let mut segments = 0;
    let (mut re, mut im) = (vec![0.0; len], vec![0.0; len]);
    let mut start = 0;
    while start + len <= x.len() {
        let seg = &x[start..start + len];
        let mean = seg.iter().sum::<f64>() / len as f64;
        for k in 0..len {
            re[k] = (seg[k] - mean) * window[k];
            im[k] = 0.0;
        }
        fft(&mut re, &mut im);
        for (j, sj) in s.iter_mut().enumerate() {
            let p = re[j] * re[j] + im[j] * im[j];
            let one_sided = if j == 0 || j == half { 1.0 } else { 2.0 };
            *sj += one_sided * dt * p / (2.0 * PI * w2);
        }
        segments += 1;
        start += half;
    }
    let dw = 2.0 * PI / (len as f64 * dt);
    let omega = (0..=half).map(|j| j as f64 * dw).collect();
    s.iter_mut().for_each(|v| *v /= f64::from(segments));
    (omega, s)
}

/// The spectral peak period 2π/ω_p of `x` sampled every `dt` s: ω_p the maximum of its
/// Welch spectrum smoothed by a five-bin running mean, refined by the parabola through the logarithms of the largest value and
/// its two neighbours (see the module documentation). NaN if `x` is constant or too short.
#[must_use]
pub fn peak_period(x: &[f64], dt: f64) -> f64 {
    let (w, raw) = welch(x, dt);
    // a five-bin running mean (±0.05 rad/s at 256-s segments) calms the estimate's scatter
    let s: Vec<f64> = (0..raw.len())
        .map(|j| {
            let (a, b) = (j.saturating_sub(2), (j + 3).min(raw.len()));
            raw[a..b].iter().sum::<f64>() / (b - a) as f64
        })
        .collect();
    let Some(k) = (1..s.len().saturating_sub(1)).max_by(|&a, &b| s[a].total_cmp(&s[b])) else {
        return f64::NAN;
    };
    if s[k] <= 0.0 || s[k - 1] <= 0.0 || s[k + 1] <= 0.0 {
        return 2.0 * PI / w[k];
    }
    let (a, b, c) = (s[k - 1].ln(), s[k].ln(), s[k + 1].ln());
    let curvature = a - 2.0 * b + c;
    let shift = if curvature < 0.0 {
        (0.5 * (a - c) / curvature).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    2.0 * PI / (w[k] + shift * (w[1] - w[0]))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;

    #[test]
    fn a_sine_has_its_variance_under_the_welch_spectrum_and_its_period_at_the_peak() {
        let dt = 0.1;
        let (a, w0) = (1.5, 2.0 * PI / 8.0);
        let x: Vec<f64> = (0..18_000).map(|k| a * (w0 * k as f64 * dt).cos()).collect();
        assert!((std(&x) - a / 2f64.sqrt()).abs() < 1e-3);
        let (w, s) = welch(&x, dt);
        let area: f64 = s.iter().sum::<f64>() * (w[1] - w[0]);
        assert!((area / (a * a / 2.0) - 1.0).abs() < 0.01, "{area}");
        assert!((peak_period(&x, dt) / 8.0 - 1.0).abs() < 0.01);
    }

    #[test]
    fn the_fft_matches_a_direct_dft() {
        let n = 64;
        let x: Vec<f64> = (0..n).map(|k| ((k * k) % 7) as f64 - 3.0).collect();
        let (mut re, mut im) = (x.clone(), vec![0.0; n]);
        fft(&mut re, &mut im);
        for j in [0, 1, 5, 31, 32, 63] {
            let (mut r, mut i) = (0.0, 0.0);
            for (k, v) in x.iter().enumerate() {
                let ang = -2.0 * PI * (j * k) as f64 / n as f64;
                r += v * ang.cos();
                i += v * ang.sin();
            }
            assert!((re[j] - r).abs() < 1e-9 && (im[j] - i).abs() < 1e-9);
        }
    }
}
