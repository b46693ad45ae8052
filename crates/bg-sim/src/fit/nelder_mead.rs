//! Derivative-free minimisers over a box: Nelder–Mead (the fit's comparison,
//! `--method nelder-mead`) and a particle swarm whose particles run in parallel
//! (`bg-sim optimize`). Both work in the unit cube `u = (p − lo)/(hi − lo)`, so the
//! parameters' units do not matter, and clamp to it.

use rayon::prelude::*;

/// What a derivative-free search found.
#[derive(Clone, Debug)]
pub struct Found {
    /// The best point.
    pub p: Vec<f64>,
    /// Its value.
    pub f: f64,
    /// Best value after each iteration (generation).
    pub history: Vec<f64>,
    /// Function evaluations.
    pub evaluations: usize,
    /// Whether the tolerance (not the budget) ended it.
    pub converged: bool,
}

fn to_p(u: &[f64], lo: &[f64], hi: &[f64]) -> Vec<f64> {
    u.iter()
        .zip(lo.iter().zip(hi))
        .map(|(u, (l, h))| l + u.clamp(0.0, 1.0) * (h - l))
        .collect()
}

/// Nelder–Mead (standard coefficients 1, 2, ½, ½) from `p0`, the first simplex 10 % of the
/// box along each axis; stops when the values of the simplex agree within `ftol` (relative)
/// or after `max_evaluations`.
pub fn nelder_mead(
    f: &(dyn Fn(&[f64]) -> f64 + Sync),
    p0: &[f64],
    lo: &[f64],
    hi: &[f64],
    ftol: f64,
    max_evaluations: usize,
) -> Found {
    let n = p0.len();
    let u0: Vec<f64> = p0
        .iter()
        .zip(lo.iter().zip(hi))
        .map(|(p, (l, h))| (p - l) / (h - l))
        .collect();
    let eval = |u: &[f64]| {
        let v = f(&to_p(u, lo, hi));
        if v.is_finite() {
            v
        } else {
            f64::INFINITY
        }
    };
    let mut simplex: Vec<Vec<f64>> = vec![u0.clone()];
    for k in 0..n {
        let mut u = u0.clone();
        u[k] = if u[k] + 0.1 <= 1.0 {
            u[k] + 0.1
        } else {
            u[k] - 0.1
        };
        simplex.push(u);
    }
    let mut values: Vec<f64> = simplex.par_iter().map(|u| eval(u)).collect();
    let mut evaluations = n + 1;
    let mut history = Vec::new();
    let mut converged = false;
    while evaluations < max_evaluations {
        let mut order: Vec<usize> = (0..=n).collect();
        order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
        simplex = order.iter().map(|&i| simplex[i].clone()).collect();
        values = order.iter().map(|&i| values[i]).collect();
        history.push(values[0]);
        if (values[n] - values[0]).abs() <= ftol * values[0].abs().max(1e-300) {
            converged = true;
            break;
        }
        #[allow(clippy::cast_precision_loss)]
        let centroid: Vec<f64> = (0..n)
            .map(|k| simplex[..n].iter().map(|u| u[k]).sum::<f64>() / n as f64)
            .collect();
        let along = |t: f64| -> Vec<f64> {
            centroid
                .iter()
                .zip(&simplex[n])
                .map(|(c, w)| (c + t * (c - w)).clamp(0.0, 1.0))
                .collect()
        };
        let xr = along(1.0);
        let fr = eval(&xr);
        evaluations += 1;
        if fr < values[0] {
            let xe = along(2.0);
            let fe = eval(&xe);
            evaluations += 1;
            if fe < fr {
                simplex[n] = xe;
                values[n] = fe;
            } else {
                simplex[n] = xr;
                values[n] = fr;
            }
        } else if fr < values[n - 1] {
            simplex[n] = xr;
            values[n] = fr;
        } else {
            let xc = if fr < values[n] {
                along(0.5)
            } else {
                along(-0.5)
            };
            let fc = eval(&xc);
            evaluations += 1;
            if fc < values[n].min(fr) {
                simplex[n] = xc;
                values[n] = fc;
            } else {
                // shrink towards the best, the n new points in parallel
                let best = simplex[0].clone();
                let shrunk: Vec<Vec<f64>> = simplex[1..]
                    .iter()
                    .map(|u| {
                        u.iter()
                            .zip(&best)
                            .map(|(x, b)| b + 0.5 * (x - b))
                            .collect()
                    })
                    .collect();
                let fs: Vec<f64> = shrunk.par_iter().map(|u| eval(u)).collect();
                evaluations += n;
                for (k, (u, v)) in shrunk.into_iter().zip(fs).enumerate() {
                    simplex[k + 1] = u;
                    values[k + 1] = v;
                }
            }
        }
    }
    let best = (0..=n)
        .min_by(|&a, &b| values[a].total_cmp(&values[b]))
        .unwrap_or(0);
    Found {
        p: to_p(&simplex[best], lo, hi),
        f: values[best],
        history,
        evaluations,
        converged,
    }
}

/// SplitMix64: small, seedable, the same on every platform (as the sweep's designs).
pub struct SplitMix(pub u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        #[allow(clippy::cast_precision_loss)]
        let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        u
    }
}

/// A particle swarm (inertia 0.7298, pulls 1.49618 to the particle's best and the swarm's:
/// Clerc's constriction) of `particles` in the box, `generations` at most, each
/// generation's particles evaluated in parallel on the current rayon pool. Stops early when
/// the swarm's best has not improved by `ftol` (relative) in 15 generations. Seeded.
#[allow(clippy::too_many_arguments)]
pub fn particle_swarm(
    f: &(dyn Fn(&[f64]) -> f64 + Sync),
    p0: Option<&[f64]>,
    lo: &[f64],
    hi: &[f64],
    particles: usize,
    generations: usize,
    ftol: f64,
    seed: u64,
) -> Found {
    let n = lo.len();
    let mut rng = SplitMix(seed);
    let mut x: Vec<Vec<f64>> = (0..particles)
        .map(|_| (0..n).map(|_| rng.unit()).collect())
        .collect();
    if let (Some(p0), Some(first)) = (p0, x.first_mut()) {
        *first = p0
            .iter()
            .zip(lo.iter().zip(hi))
            .map(|(p, (l, h))| ((p - l) / (h - l)).clamp(0.0, 1.0))
            .collect();
    }
    let mut v: Vec<Vec<f64>> = (0..particles)
        .map(|_| (0..n).map(|_| 0.2 * (rng.unit() - 0.5)).collect())
        .collect();
    let eval_all = |x: &[Vec<f64>]| -> Vec<f64> {
        x.par_iter()
            .map(|u| {
                let y = f(&to_p(u, lo, hi));
                if y.is_finite() {
                    y
                } else {
                    f64::INFINITY
                }
            })
            .collect()
    };
    let mut fx = eval_all(&x);
    let mut evaluations = particles;
    let mut best_x = x.clone();
    let mut best_f = fx.clone();
    let mut g = (0..particles)
        .min_by(|&a, &b| fx[a].total_cmp(&fx[b]))
        .unwrap_or(0);
    let mut history = vec![best_f[g]];
    let mut stale = 0;
    let mut converged = false;
    for _ in 1..generations {
        for i in 0..particles {
            for k in 0..n {
                let (r1, r2) = (rng.unit(), rng.unit());
                v[i][k] = 0.7298 * v[i][k]
                    + 1.49618 * r1 * (best_x[i][k] - x[i][k])
                    + 1.49618 * r2 * (best_x[g][k] - x[i][k]);
                x[i][k] = (x[i][k] + v[i][k]).clamp(0.0, 1.0);
            }
        }
        fx = eval_all(&x);
        evaluations += particles;
        let before = best_f[g];
        for i in 0..particles {
            if fx[i] < best_f[i] {
                best_f[i] = fx[i];
                best_x[i].clone_from(&x[i]);
            }
        }
        g = (0..particles)
            .min_by(|&a, &b| best_f[a].total_cmp(&best_f[b]))
            .unwrap_or(0);
        history.push(best_f[g]);
        if before - best_f[g] <= ftol * before.abs().max(1e-300) {
            stale += 1;
            if stale >= 15 {
                converged = true;
                break;
            }
        } else {
            stale = 0;
        }
    }
    Found {
        p: to_p(&best_x[g], lo, hi),
        f: best_f[g],
        history,
        evaluations,
        converged,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rosen(p: &[f64]) -> f64 {
        100.0 * (p[1] - p[0] * p[0]).powi(2) + (1.0 - p[0]).powi(2)
    }

    #[test]
    fn nelder_mead_finds_the_rosenbrock_minimum() {
        let r = nelder_mead(
            &rosen,
            &[-1.2, 1.0],
            &[-2.0, -2.0],
            &[2.0, 2.0],
            1e-14,
            5000,
        );
        assert!(
            (r.p[0] - 1.0).abs() < 1e-3 && (r.p[1] - 1.0).abs() < 2e-3,
            "{:?}",
            r.p
        );
        assert!(r.converged);
    }

    #[test]
    fn the_swarm_finds_a_bounded_minimum_and_is_reproducible() {
        // (x − 3)² + (y + 1)² in [0, 2] × [−2, 2]: the minimum at the bound x = 2, y = −1
        let f = |p: &[f64]| (p[0] - 3.0).powi(2) + (p[1] + 1.0).powi(2);
        let a = particle_swarm(&f, None, &[0.0, -2.0], &[2.0, 2.0], 16, 200, 1e-12, 7);
        assert!(
            (a.p[0] - 2.0).abs() < 1e-4 && (a.p[1] + 1.0).abs() < 1e-3,
            "{:?}",
            a.p
        );
        let b = particle_swarm(&f, None, &[0.0, -2.0], &[2.0, 2.0], 16, 200, 1e-12, 7);
        assert_eq!(a.p, b.p);
    }
}
