//! Micro-benchmark of the Radau5 LU kernels: µs per factorisation (forming diag·I − J
//! included) and per solve, real and complex, for the kernel in `src/lu/` ("new"),
//! the previous one (`old.rs`, `Complex<f64>` elements), faer 0.24's partial-pivot LU, and
//! the complex system as a real 2n×2n one on the new real kernel ("2n").
//!
//! ```text
//! cargo run --release -p bg-sim --example dump_jacobian -- models/knuckle_boom.toml /tmp/j38.txt
//! cargo run --release -p bg-solver --example lu_bench -- /tmp/j38.txt   # crane Jacobians
//! cargo run --release -p bg-solver --example lu_bench                   # random dense
//! ```
//! Each case is the minimum over rounds (the machine is shared); "diff" is the largest
//! relative difference of the solutions from the old kernel's.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

#[path = "../../src/lu/mod.rs"]
mod lu;
mod old;
use lu as new;

use std::hint::black_box;
use std::time::Instant;

use faer::c64;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor as ffactor, solve as fsolve};
use faer::{MatMut, MatRef, Par};
use nalgebra::Complex;

/// γ and α ± iβ of Radau IIA order 5 (the inverse of A's eigenvalues).
const GAMMA: f64 = 3.637_834_252_744_496;
const ALPHA: f64 = 2.681_082_873_627_752;
const BETA: f64 = 3.050_430_199_247_411;

/// The Jacobians of a `dump_jacobian` file, column-major.
fn read_jacobians(path: &str) -> (usize, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut it = text.split_whitespace();
    let n: usize = it.next().unwrap().parse().unwrap();
    let vals: Vec<f64> = it.map(|v| v.parse().unwrap()).collect();
    let mats = vals
        .chunks_exact(n * n)
        .map(|rows| {
            let mut cm = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    cm[j * n + i] = rows[i * n + j];
                }
            }
            cm
        })
        .collect();
    (n, mats)
}

/// Dense J with entries uniform in ±scale.
fn random_jac(n: usize, seed: u64, scale: f64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
    (0..n * n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * scale
        })
        .collect()
}

/// The minimum over 15 rounds of the time per call, in µs.
fn time(mut f: impl FnMut()) -> f64 {
    let mut reps = 1;
    loop {
        let start = Instant::now();
        for _ in 0..reps {
            f();
        }
        if start.elapsed().as_secs_f64() > 2e-3 {
            break;
        }
        reps *= 2;
    }
    (0..15)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..reps {
                f();
            }
            start.elapsed().as_secs_f64() / reps as f64 * 1e6
        })
        .fold(f64::INFINITY, f64::min)
}

#[derive(Default, Clone, Copy)]
struct Times {
    lu_r: f64,
    lu_c: f64,
    sol_r: f64,
    sol_c: f64,
}

impl std::ops::AddAssign for Times {
    fn add_assign(&mut self, o: Self) {
        self.lu_r += o.lu_r;
        self.lu_c += o.lu_c;
        self.sol_r += o.sol_r;
        self.sol_c += o.sol_c;
    }
}

/// The solutions of a case, real and complex.
type Solution = (Vec<f64>, Vec<Complex<f64>>);

fn rhs(n: usize) -> (Vec<f64>, Vec<Complex<f64>>) {
    let b: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64).sin()).collect();
    let bc = b.iter().map(|&v| Complex::new(v, 0.5 - v)).collect();
    (b, bc)
}

fn bench_old(n: usize, jac: &[f64], h: f64, x: &mut Solution) -> Times {
    let mut r = old::DenseLu::<f64>::new(n);
    let mut c = old::DenseLu::<Complex<f64>>::new(n);
    let cshift = Complex::new(ALPHA / h, BETA / h);
    let lu_r = time(|| {
        r.set_shifted(GAMMA / h, black_box(jac), |v| v);
        r.factor().unwrap();
    });
    let lu_c = time(|| {
        c.set_shifted(cshift, black_box(jac), |v| Complex::new(v, 0.0));
        c.factor().unwrap();
    });
    let (b, bc) = rhs(n);
    let mut y = b.clone();
    let sol_r = time(|| {
        y.copy_from_slice(&b);
        r.solve(black_box(&mut y));
    });
    let mut yc = bc.clone();
    let sol_c = time(|| {
        yc.copy_from_slice(&bc);
        c.solve(black_box(&mut yc));
    });
    *x = (y, yc);
    Times {
        lu_r,
        lu_c,
        sol_r,
        sol_c,
    }
}

fn bench_new(n: usize, jac: &[f64], h: f64, x: &mut Solution) -> Times {
    let mut r = new::RealLu::new(n);
    let mut c = new::ComplexLu::new(n);
    let cshift = Complex::new(ALPHA / h, BETA / h);
    let lu_r = time(|| {
        r.set_shifted(GAMMA / h, black_box(jac));
        r.factor().unwrap();
    });
    let lu_c = time(|| {
        c.set_shifted(cshift, black_box(jac));
        c.factor().unwrap();
    });
    let (b, bc) = rhs(n);
    let (bre, bim): (Vec<f64>, Vec<f64>) = bc.iter().map(|v| (v.re, v.im)).unzip();
    let mut y = b.clone();
    let sol_r = time(|| {
        y.copy_from_slice(&b);
        r.solve(black_box(&mut y));
    });
    let (mut yr, mut yi) = (bre.clone(), bim.clone());
    let sol_c = time(|| {
        yr.copy_from_slice(&bre);
        yi.copy_from_slice(&bim);
        c.solve(black_box(&mut yr), black_box(&mut yi));
    });
    let yc = yr
        .iter()
        .zip(&yi)
        .map(|(&r, &i)| Complex::new(r, i))
        .collect();
    *x = (y, yc);
    Times {
        lu_r,
        lu_c,
        sol_r,
        sol_c,
    }
}

/// The complex system as the real [[αI − J, −βI], [βI, αI − J]] (scaled by 1/h) on the new
/// real kernel; only the complex columns are filled.
fn bench_2n(n: usize, jac: &[f64], h: f64, x: &mut Solution) -> Times {
    let m = 2 * n;
    // J2 = −(M − diag): M's off-diagonal blocks ∓β/h, diagonal blocks α/h − J.
    let mut j2 = vec![0.0; m * m];
    for j in 0..n {
        for i in 0..n {
            j2[j * m + i] = jac[j * n + i];
            j2[(j + n) * m + i + n] = jac[j * n + i];
        }
        j2[(j + n) * m + j] = BETA / h;
        j2[j * m + j + n] = -BETA / h;
    }
    let mut r = new::RealLu::new(m);
    let lu_c = time(|| {
        r.set_shifted(ALPHA / h, black_box(&j2));
        r.factor().unwrap();
    });
    let (_, bc) = rhs(n);
    let b: Vec<f64> = bc
        .iter()
        .map(|v| v.re)
        .chain(bc.iter().map(|v| v.im))
        .collect();
    let mut y = b.clone();
    let sol_c = time(|| {
        y.copy_from_slice(&b);
        r.solve(black_box(&mut y));
    });
    x.1 = (0..n).map(|i| Complex::new(y[i], y[i + n])).collect();
    Times {
        lu_r: f64::NAN,
        lu_c,
        sol_r: f64::NAN,
        sol_c,
    }
}

fn bench_faer(n: usize, jac: &[f64], h: f64, x: &mut Solution) -> Times {
    let mut a = vec![0.0f64; n * n];
    let mut ac = vec![c64::new(0.0, 0.0); n * n];
    let (mut perm, mut perm_inv) = (vec![0usize; n], vec![0usize; n]);
    let (mut cperm, mut cperm_inv) = (vec![0usize; n], vec![0usize; n]);
    let req = ffactor::lu_in_place_scratch::<usize, c64>(n, n, Par::Seq, Default::default())
        .or(fsolve::solve_in_place_scratch::<usize, c64>(n, 1, Par::Seq));
    let mut buf = MemBuffer::new(req);
    let stack = MemStack::new(&mut buf);
    let lu_r = time(|| {
        for (d, &j) in a.iter_mut().zip(black_box(jac)) {
            *d = -j;
        }
        for k in 0..n {
            a[k * n + k] += GAMMA / h;
        }
        let m = MatMut::from_column_major_slice_mut(&mut a, n, n);
        ffactor::lu_in_place(
            m,
            &mut perm,
            &mut perm_inv,
            Par::Seq,
            stack,
            Default::default(),
        );
    });
    let cshift = c64::new(ALPHA / h, BETA / h);
    let lu_c = time(|| {
        for (d, &j) in ac.iter_mut().zip(black_box(jac)) {
            *d = c64::new(-j, 0.0);
        }
        for k in 0..n {
            ac[k * n + k] += cshift;
        }
        let m = MatMut::from_column_major_slice_mut(&mut ac, n, n);
        ffactor::lu_in_place(
            m,
            &mut cperm,
            &mut cperm_inv,
            Par::Seq,
            stack,
            Default::default(),
        );
    });
    // The last timed call left the factors in a and ac.
    let (b, bc) = rhs(n);
    let mut y = b.clone();
    let p = faer::perm::PermRef::new_checked(&perm, &perm_inv, n);
    let lu = MatRef::from_column_major_slice(&a, n, n);
    let sol_r = time(|| {
        y.copy_from_slice(&b);
        let rhs = MatMut::from_column_major_slice_mut(black_box(&mut y), n, 1);
        fsolve::solve_in_place(lu, lu, p, rhs, Par::Seq, stack);
    });
    let mut yc = bc.clone();
    let pc = faer::perm::PermRef::new_checked(&cperm, &cperm_inv, n);
    let luc = MatRef::from_column_major_slice(&ac, n, n);
    let sol_c = time(|| {
        yc.copy_from_slice(&bc);
        let rhs = MatMut::from_column_major_slice_mut(black_box(&mut yc), n, 1);
        fsolve::solve_in_place(luc, luc, pc, rhs, Par::Seq, stack);
    });
    *x = (y, yc);
    Times {
        lu_r,
        lu_c,
        sol_r,
        sol_c,
    }
}

/// Largest difference of b's solutions from a's, relative to a's largest entry.
fn max_rel_diff(a: &Solution, b: &Solution) -> f64 {
    let rel = |d: f64, s: f64| if d == 0.0 { 0.0 } else { d / s };
    let scale_r = a.0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale_c = a.1.iter().fold(0.0f64, |m, v| m.max(v.norm()));
    let dr =
        a.0.iter()
            .zip(&b.0)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    let dc =
        a.1.iter()
            .zip(&b.1)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).norm()));
    if b.0.is_empty() {
        rel(dc, scale_c)
    } else {
        rel(dr, scale_r).max(rel(dc, scale_c))
    }
}

type Bench = fn(usize, &[f64], f64, &mut Solution) -> Times;

/// Mean over the Jacobians and step sizes, per kernel.
fn report(label: &str, n: usize, jacs: &[Vec<f64>], hs: &[f64]) {
    let kernels: [(&str, Bench); 4] = [
        ("old", bench_old),
        ("new", bench_new),
        ("faer", bench_faer),
        ("2n", bench_2n),
    ];
    let mut times = [Times::default(); 4];
    let mut diffs = [0.0f64; 4];
    let cases = (jacs.len() * hs.len()) as f64;
    for jac in jacs {
        for &h in hs {
            let mut reference = Solution::default();
            for (k, (_, bench)) in kernels.iter().enumerate() {
                let mut x = Solution::default();
                times[k] += bench(n, jac, h, &mut x);
                if k == 0 {
                    reference = x;
                } else {
                    diffs[k] = diffs[k].max(max_rel_diff(&reference, &x));
                }
            }
        }
    }
    for ((name, _), (t, d)) in kernels.iter().zip(times.iter().zip(diffs)) {
        println!(
            "{label:>6} n={n:3} {name:>4}: LU real {:7.2} complex {:7.2}   solve real {:5.2} complex {:5.2} µs   (diff {d:.0e})",
            t.lu_r / cases,
            t.lu_c / cases,
            t.sol_r / cases,
            t.sol_c / cases
        );
    }
}

/// `LU_PROFILE=real|complex`: factorise the first file's Jacobians for 3 s, for `perf`.
fn profile(what: &str, path: &str) {
    let (n, jacs) = read_jacobians(path);
    let (mut r, mut c) = (new::RealLu::new(n), new::ComplexLu::new(n));
    let start = Instant::now();
    let mut calls = 0;
    while start.elapsed().as_secs_f64() < 3.0 {
        for jac in &jacs {
            for h in [1e-4, 1e-3, 1e-2] {
                if what == "real" {
                    r.set_shifted(GAMMA / h, jac);
                    r.factor().unwrap();
                } else {
                    c.set_shifted(Complex::new(ALPHA / h, BETA / h), jac);
                    c.factor().unwrap();
                }
                calls += 1;
            }
        }
    }
    println!("{what}: {:.2} µs per factorisation", 3e6 / f64::from(calls));
}

/// `LU_COUNT=real|complex|solve`: a fixed amount of work on the first file's Jacobians
/// (each factorised at h = 1e-4, 1e-3, 1e-2, `LU_REPS` times, default 10), for instruction
/// counts under `valgrind --tool=callgrind` (per call: the function's inclusive count over
/// the number of calls printed).
fn count(what: &str, path: &str) {
    let (n, jacs) = read_jacobians(path);
    let reps: usize = std::env::var("LU_REPS").map_or(10, |v| v.parse().unwrap());
    let (mut r, mut c) = (new::RealLu::new(n), new::ComplexLu::new(n));
    let (b, bc) = rhs(n);
    let (bre, bim): (Vec<f64>, Vec<f64>) = bc.iter().map(|v| (v.re, v.im)).unzip();
    let (mut y, mut yr, mut yi) = (b.clone(), bre.clone(), bim.clone());
    let mut calls = 0;
    let mut check = 0.0;
    for _ in 0..reps {
        for jac in &jacs {
            for h in [1e-4, 1e-3, 1e-2] {
                if what != "complex" {
                    r.set_shifted(GAMMA / h, black_box(jac));
                    r.factor().unwrap();
                }
                if what != "real" {
                    c.set_shifted(Complex::new(ALPHA / h, BETA / h), black_box(jac));
                    c.factor().unwrap();
                }
                if what == "solve" {
                    y.copy_from_slice(&b);
                    r.solve(black_box(&mut y));
                    yr.copy_from_slice(&bre);
                    yi.copy_from_slice(&bim);
                    c.solve(black_box(&mut yr), black_box(&mut yi));
                    check += y[0] + yr[0] + yi[0];
                }
                calls += 1;
            }
        }
    }
    println!("{what}: {calls} calls (check {check:e})");
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let (Ok(what), Some(path)) = (std::env::var("LU_PROFILE"), args.first()) {
        profile(&what, path);
        return;
    }
    if let (Ok(what), Some(path)) = (std::env::var("LU_COUNT"), args.first()) {
        count(&what, path);
        return;
    }
    for path in &args {
        let (n, jacs) = read_jacobians(path);
        report("crane", n, &jacs, &[1e-4, 1e-3, 1e-2]);
    }
    if args.is_empty() {
        for n in [5, 10, 20, 38, 66, 100] {
            let jacs: Vec<Vec<f64>> = (0..2).map(|s| random_jac(n, s, 1e4)).collect();
            report("random", n, &jacs, &[1e-3]);
        }
    }
}
