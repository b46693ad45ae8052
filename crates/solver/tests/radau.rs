//! The Radau IIA integrator on its own: linear problems against closed forms, stiff
//! nonlinear benchmarks (Robertson, Van der Pol) against reference values, convergence with
//! the tolerance, dense output, stop times, restarts and failures.
//!
//! Tolerances are stated at each assertion; the work figures asserted (steps, rhs, Jacobians,
//! LU) are upper bounds about 25 % above what the integrator needed when the test was
//! written, so a regression in the step-size or reuse logic shows up.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_solver::radau::*;

/// An ODE from two closures: f(t, y, dy) and J(t, y, jac).
struct Sys<F, J> {
    n: usize,
    f: F,
    j: J,
}

impl<F, J> OdeSystem for Sys<F, J>
where
    F: FnMut(f64, &[f64], &mut [f64]),
    J: FnMut(f64, &[f64], &mut DMatrix<f64>),
{
    fn n(&self) -> usize {
        self.n
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        (self.f)(t, y, dy);
    }
    fn jacobian(&mut self, t: f64, y: &[f64], _fy: &[f64], jac: &mut DMatrix<f64>) {
        (self.j)(t, y, jac);
    }
}

fn sys<F, J>(n: usize, f: F, j: J) -> Sys<F, J>
where
    F: FnMut(f64, &[f64], &mut [f64]),
    J: FnMut(f64, &[f64], &mut DMatrix<f64>),
{
    Sys { n, f, j }
}

fn opts(rtol: f64, atol: f64) -> RadauOptions {
    RadauOptions {
        rtol,
        atol: vec![atol],
        ..RadauOptions::default()
    }
}

/// Step until `t_end`, calling `each` after every accepted step; panics after 10⁶ steps.
fn run(
    s: &mut impl OdeSystem,
    r: &mut Radau5,
    t_end: f64,
    mut each: impl FnMut(&Radau5, &StepReport),
) -> Result<(), RadauError> {
    for _ in 0..1_000_000 {
        let rep = r.step(s, t_end)?;
        assert!(rep.t <= t_end, "stepped past t_stop: {} > {t_end}", rep.t);
        each(r, &rep);
        if rep.reached_stop {
            return Ok(());
        }
    }
    panic!("no end after 10⁶ steps at t = {}", r.t());
}

fn decay(k: f64) -> impl OdeSystem {
    sys(
        1,
        move |_t, y: &[f64], dy: &mut [f64]| dy[0] = -k * y[0],
        move |_t, _y: &[f64], j: &mut DMatrix<f64>| j[(0, 0)] = -k,
    )
}

/// x' = ωv, v' = −ωx: an undamped mode, both components of amplitude 1.
fn oscillator(omega: f64) -> impl OdeSystem {
    sys(
        2,
        move |_t, y: &[f64], dy: &mut [f64]| {
            dy[0] = omega * y[1];
            dy[1] = -omega * y[0];
        },
        // J = |  0  ω |
        //     | −ω  0 |
        move |_t, _y: &[f64], j: &mut DMatrix<f64>| {
            j.fill(0.0);
            j[(0, 1)] = omega;
            j[(1, 0)] = -omega;
        },
    )
}

/// y' = −ky: y(t) = e^(−kt), relative error at the end ≤ rtol, and at every step ≤ rtol.
#[test]
fn exponential_decay_matches_the_closed_form() {
    let mut s = decay(2.0);
    let mut r = Radau5::new(&mut s, 0.0, &[1.0], opts(1e-6, 1e-12)).unwrap();
    let mut worst = 0.0f64;
    run(&mut s, &mut r, 5.0, |r, _| {
        let exact = (-2.0 * r.t()).exp();
        worst = worst.max((r.y()[0] - exact).abs() / exact);
    })
    .unwrap();
    assert!(worst < 1e-6, "worst relative error {worst:e}");
    assert!(r.stats().steps < 125, "{:?}", r.stats());
}

/// A 100 Hz undamped mode over 100 periods (the crane's bending modes reach ~170 Hz): at
/// rtol 1e-6 the error against the exact solution stays below 3e-6 (amplitude 1) and the
/// amplitude, which Radau IIA damps slightly (|R(iωh)| < 1), stays within 3e-6 of 1.
#[test]
fn undamped_oscillator_keeps_its_amplitude_over_many_periods() {
    let omega = 2.0 * std::f64::consts::PI * 100.0;
    let mut s = oscillator(omega);
    let mut r = Radau5::new(&mut s, 0.0, &[0.0, 1.0], opts(1e-6, 1e-9)).unwrap();
    let (mut worst, mut worst_amp) = (0.0f64, 0.0f64);
    run(&mut s, &mut r, 1.0, |r, _| {
        let (x, v) = (r.y()[0], r.y()[1]);
        let (xe, ve) = ((omega * r.t()).sin(), (omega * r.t()).cos());
        worst = worst.max((x - xe).abs()).max((v - ve).abs());
        worst_amp = worst_amp.max((x.hypot(v) - 1.0).abs());
    })
    .unwrap();
    println!(
        "oscillator: worst error {worst:e}, amplitude drift {worst_amp:e}, {:?}",
        r.stats()
    );
    assert!(worst < 3e-6, "worst error {worst:e}");
    assert!(worst_amp < 3e-6, "amplitude drift {worst_amp:e}");
    // One Jacobian for a linear problem; about 60 steps per period at this tolerance.
    let st = r.stats();
    assert!(
        st.steps < 7600 && st.jacobians == 1 && st.lu_decompositions < 20,
        "{st:?}"
    );
}

/// Eigenvalues −1 and −10⁶: y' = My, M = ½[[−(10⁶+1), 10⁶−1], [10⁶−1, −(10⁶+1)]], y(0) =
/// (2, 0): y = (e^(−t) + e^(−10⁶t), e^(−t) − e^(−10⁶t)). Error ≤ 1e-6 after the transient
/// (t ≥ 1e-4), and the steps follow the slow mode, not the fast one (under 185 steps on
/// [0, 10], where an explicit method would need millions).
#[test]
fn stiff_linear_system_follows_the_slow_mode_with_few_steps() {
    let (a, b) = (-(1e6 + 1.0) / 2.0, (1e6 - 1.0) / 2.0);
    let mut s = sys(
        2,
        move |_t, y: &[f64], dy: &mut [f64]| {
            dy[0] = a * y[0] + b * y[1];
            dy[1] = b * y[0] + a * y[1];
        },
        // J = | a b |
        //     | b a |
        move |_t, _y: &[f64], j: &mut DMatrix<f64>| {
            *j = DMatrix::from_row_slice(2, 2, &[a, b, b, a]);
        },
    );
    let mut r = Radau5::new(&mut s, 0.0, &[2.0, 0.0], opts(1e-6, 1e-10)).unwrap();
    let mut worst = 0.0f64;
    run(&mut s, &mut r, 10.0, |r, _| {
        let (slow, fast) = ((-r.t()).exp(), (-1e6 * r.t()).exp());
        if r.t() >= 1e-4 {
            worst = worst
                .max((r.y()[0] - (slow + fast)).abs())
                .max((r.y()[1] - (slow - fast)).abs());
        }
    })
    .unwrap();
    println!("stiff linear: worst {worst:e}, {:?}", r.stats());
    assert!(worst < 1e-6, "worst error {worst:e}");
    assert!(r.stats().steps < 185, "{:?}", r.stats());
}

/// Prothero–Robinson, y' = λ(y − sin t) + cos t with λ = −10⁶, y(0) = 0: y = sin t.
/// Error ≤ 1e-6 at every step on [0, 10] at rtol = atol = 1e-6, in under 20 steps.
#[test]
fn prothero_robinson_stays_on_the_smooth_solution() {
    let lam = -1e6;
    let mut s = sys(
        1,
        move |t, y: &[f64], dy: &mut [f64]| dy[0] = lam * (y[0] - t.sin()) + t.cos(),
        move |_t, _y: &[f64], j: &mut DMatrix<f64>| j[(0, 0)] = lam,
    );
    let mut r = Radau5::new(&mut s, 0.0, &[0.0], opts(1e-6, 1e-6)).unwrap();
    let mut worst = 0.0f64;
    run(&mut s, &mut r, 10.0, |r, _| {
        worst = worst.max((r.y()[0] - r.t().sin()).abs());
    })
    .unwrap();
    println!("Prothero–Robinson: worst {worst:e}, {:?}", r.stats());
    assert!(worst < 1e-6, "worst error {worst:e}");
    assert!(r.stats().steps < 20, "{:?}", r.stats());
}

/// Robertson's chemical kinetics, the classic stiff test.
fn robertson() -> impl OdeSystem {
    sys(
        3,
        |_t, y: &[f64], dy: &mut [f64]| {
            dy[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
            dy[2] = 3e7 * y[1] * y[1];
            dy[1] = -dy[0] - dy[2];
        },
        // J = | −0.04          1e4·y₃           1e4·y₂ |
        //     |  0.04   −1e4·y₃ − 6e7·y₂       −1e4·y₂ |
        //     |  0                 6e7·y₂            0 |
        |_t, y: &[f64], j: &mut DMatrix<f64>| {
            *j = DMatrix::from_row_slice(
                3,
                3,
                &[
                    -0.04,
                    1e4 * y[2],
                    1e4 * y[1],
                    0.04,
                    -1e4 * y[2] - 6e7 * y[1],
                    -1e4 * y[1],
                    0.0,
                    6e7 * y[1],
                    0.0,
                ],
            );
        },
    )
}

/// Robertson at t = 40 against the literature values (Hairer & Wanner II, IV.10:
/// y(40) = (0.7158271, 9.185535e-6, 0.2841637)), relative error ≤ 1e-5 per component at
/// rtol 1e-7; then on to t = 4·10¹⁰, conserving y₁ + y₂ + y₃ = 1 within 1e-6 with no
/// component below −1e-10, in under 720 steps.
#[test]
fn robertson_matches_the_reference_and_runs_to_4e10() {
    let mut s = robertson();
    let o = RadauOptions {
        rtol: 1e-7,
        atol: vec![1e-10, 1e-14, 1e-10],
        ..RadauOptions::default()
    };
    let mut r = Radau5::new(&mut s, 0.0, &[1.0, 0.0, 0.0], o).unwrap();
    run(&mut s, &mut r, 40.0, |_, _| {}).unwrap();
    let want = [0.715_827_1, 9.185_535e-6, 0.284_163_7];
    for (k, (got, want)) in r.y().iter().zip(want).enumerate() {
        assert!(
            ((got - want) / want).abs() < 1e-5,
            "y{}(40) = {got:e}, literature {want:e}",
            k + 1
        );
    }
    let mut worst_sum = 0.0f64;
    let mut lowest = 0.0f64;
    run(&mut s, &mut r, 4e10, |r, _| {
        let y = r.y();
        worst_sum = worst_sum.max((y[0] + y[1] + y[2] - 1.0).abs());
        lowest = lowest.min(y[0]).min(y[1]).min(y[2]);
    })
    .unwrap();
    let st = r.stats();
    println!("Robertson to 4e10, rtol 1e-7: y = {:?}, {st:?}", r.y());
    assert!(worst_sum < 1e-6, "mass balance off by {worst_sum:e}");
    assert!(lowest > -1e-10, "a concentration fell to {lowest:e}");
    // Nearly all mass has gone to y₃ by 4e10.
    assert!(r.y()[0] < 1e-3 && r.y()[2] > 0.999, "{:?}", r.y());
    assert!(st.steps < 720 && st.jacobians < 530, "{st:?}");
}

/// Van der Pol in Hairer's scaled form, y₁' = y₂, y₂' = ((1 − y₁²)y₂ − y₁)/ε.
fn van_der_pol(eps: f64) -> impl OdeSystem {
    sys(
        2,
        move |_t, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[1];
            dy[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / eps;
        },
        // J = | 0                        1          |
        //     | (−2y₁y₂ − 1)/ε      (1 − y₁²)/ε     |
        move |_t, y: &[f64], j: &mut DMatrix<f64>| {
            *j = DMatrix::from_row_slice(
                2,
                2,
                &[
                    0.0,
                    1.0,
                    (-2.0 * y[0] * y[1] - 1.0) / eps,
                    (1.0 - y[0] * y[0]) / eps,
                ],
            );
        },
    )
}

/// y(2) of Van der Pol with ε = 10⁻⁶ from y(0) = (2, 0), as published with the Test Set for
/// IVP Solvers (Mazzia & Magherini, problem VDPOL). This integrator at rtol = atol = 1e-12
/// gives (1.7061677321703854, −0.89280970102490176): the same to 1e-13.
const VDP_Y2: [f64; 2] = [1.706_167_732_170_483, -0.892_809_701_024_797_5];

/// The tight run (rtol = atol = 1e-10, 8 756 steps) reproduces the published y(2) to 1e-11.
#[test]
fn van_der_pol_tight_run_reproduces_the_published_reference() {
    let mut s = van_der_pol(1e-6);
    let mut r = Radau5::new(&mut s, 0.0, &[2.0, 0.0], opts(1e-10, 1e-10)).unwrap();
    run(&mut s, &mut r, 2.0, |_, _| {}).unwrap();
    println!("VdP tight: y(2) = {:.16?}, {:?}", r.y(), r.stats());
    for (got, want) in r.y().iter().zip(VDP_Y2) {
        assert!((got - want).abs() < 1e-11, "{:?}", r.y());
    }
}

/// Van der Pol ε = 10⁻⁶ at rtol = atol = 1e-6: y(2) within 1e-5 of the reference, in under
/// 1 050 steps.
#[test]
fn van_der_pol_stiff_matches_the_reference() {
    let mut s = van_der_pol(1e-6);
    let mut r = Radau5::new(&mut s, 0.0, &[2.0, 0.0], opts(1e-6, 1e-6)).unwrap();
    run(&mut s, &mut r, 2.0, |_, _| {}).unwrap();
    let st = r.stats();
    println!("VdP eps=1e-6, rtol 1e-6: y(2) = {:?}, {st:?}", r.y());
    for (got, want) in r.y().iter().zip(VDP_Y2) {
        assert!((got - want).abs() < 1e-5, "{:?}", r.y());
    }
    assert!(st.steps < 1050, "{st:?}");
}

/// Van der Pol with μ = 1000 in the unscaled form y₁' = y₂, y₂' = μ(1 − y₁²)y₂ − y₁ is a
/// relaxation oscillation: over t ∈ [0, 6000] y₁ swings between about ±2 with period
/// (3 − 2 ln 2)μ + 7.014μ^(−1/3) + … ≈ 1614 (Hairer & Wanner II, VI.1); the measured periods
/// agree within 0.5 %.
#[test]
fn van_der_pol_relaxation_oscillation_has_the_asymptotic_period() {
    let mu = 1000.0;
    let mut s = sys(
        2,
        move |_t, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[1];
            dy[1] = mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
        },
        move |_t, y: &[f64], j: &mut DMatrix<f64>| {
            *j = DMatrix::from_row_slice(
                2,
                2,
                &[
                    0.0,
                    1.0,
                    -2.0 * mu * y[0] * y[1] - 1.0,
                    mu * (1.0 - y[0] * y[0]),
                ],
            );
        },
    );
    let mut r = Radau5::new(&mut s, 0.0, &[2.0, 0.0], opts(1e-6, 1e-6)).unwrap();
    // Downward zero crossings of y₁, located by bisection on the dense output.
    let mut crossings = Vec::new();
    let mut peak = 0.0f64;
    let mut buf = [0.0; 2];
    run(&mut s, &mut r, 6000.0, |r, _| {
        peak = peak.max(r.y()[0].abs());
        let (t0, t1) = (r.t_prev(), r.t());
        r.interpolate(t0, &mut buf).unwrap();
        if buf[0] > 0.0 && r.y()[0] <= 0.0 {
            let (mut a, mut b) = (t0, t1);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                r.interpolate(m, &mut buf).unwrap();
                if buf[0] > 0.0 {
                    a = m;
                } else {
                    b = m;
                }
            }
            crossings.push(0.5 * (a + b));
        }
    })
    .unwrap();
    println!("VdP mu=1e3: crossings {crossings:?}, {:?}", r.stats());
    let period = (3.0 - 2.0 * 2f64.ln()) * mu + 7.014 * mu.powf(-1.0 / 3.0);
    assert!(crossings.len() >= 3, "{crossings:?}");
    for w in crossings.windows(2) {
        let p = w[1] - w[0];
        assert!(
            (p - period).abs() < 0.005 * period,
            "period {p}, expected {period}"
        );
    }
    assert!((peak - 2.0).abs() < 0.05, "peak |y1| = {peak}");
}

/// Tightening rtol by 100 reduces the global error by a factor of at least 50 (the order-3
/// error estimate gives error ∝ rtol^(5/4) for smooth problems, a factor of ~300), on a
/// nonlinear problem with a closed form, y' = y²·cos t, y(0) = 1/2: y = 1/(2 − sin t).
#[test]
fn global_error_falls_with_rtol() {
    let mut errors = Vec::new();
    for rtol in [1e-4, 1e-6, 1e-8, 1e-10] {
        let mut s = sys(
            1,
            |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = y[0] * y[0] * t.cos(),
            |t: f64, y: &[f64], j: &mut DMatrix<f64>| j[(0, 0)] = 2.0 * y[0] * t.cos(),
        );
        let mut r = Radau5::new(&mut s, 0.0, &[0.5], opts(rtol, rtol)).unwrap();
        let mut worst = 0.0f64;
        run(&mut s, &mut r, 20.0, |r, _| {
            worst = worst.max((r.y()[0] - 1.0 / (2.0 - r.t().sin())).abs());
        })
        .unwrap();
        errors.push((rtol, worst, r.stats().steps));
    }
    println!("rtol, worst error, steps: {errors:?}");
    for w in errors.windows(2) {
        assert!(w[0].1 / w[1].1 > 50.0, "{errors:?}");
    }
    // rtol bounds the global error here.
    for (rtol, err, _) in &errors {
        assert!(err < rtol, "{errors:?}");
    }
}

/// Dense output inside every step of the 100 Hz oscillator is within 5·rtol of the exact
/// solution; at the step ends it returns the step's values exactly; outside the last step
/// it is refused.
#[test]
fn interpolation_is_accurate_inside_steps_and_exact_at_their_ends() {
    let omega = 2.0 * std::f64::consts::PI * 100.0;
    let rtol = 1e-6;
    let mut s = oscillator(omega);
    let mut r = Radau5::new(&mut s, 0.0, &[0.0, 1.0], opts(rtol, 1e-9)).unwrap();
    let mut buf = [0.0; 2];
    let mut prev = r.y().to_vec();
    let mut worst = 0.0f64;
    run(&mut s, &mut r, 0.1, |r, _| {
        let (t0, t1) = (r.t_prev(), r.t());
        r.interpolate(t1, &mut buf).unwrap();
        assert_eq!(buf.to_vec(), r.y(), "not exact at the step's end");
        r.interpolate(t0, &mut buf).unwrap();
        assert_eq!(buf.to_vec(), prev, "not exact at the step's start");
        for k in 1..10 {
            let t = t0 + (t1 - t0) * f64::from(k) / 10.0;
            r.interpolate(t, &mut buf).unwrap();
            let (xe, ve) = ((omega * t).sin(), (omega * t).cos());
            worst = worst.max((buf[0] - xe).abs()).max((buf[1] - ve).abs());
        }
        let h = t1 - t0;
        for t in [t0 - 0.01 * h, t1 + 0.01 * h] {
            assert!(matches!(
                r.interpolate(t, &mut buf),
                Err(RadauError::OutsideStep { .. })
            ));
        }
        prev = r.y().to_vec();
    })
    .unwrap();
    println!("dense output: worst error {worst:e}");
    assert!(worst < 5.0 * rtol, "worst dense-output error {worst:e}");
    assert!(matches!(
        r.interpolate(0.1, &mut [0.0; 3]),
        Err(RadauError::DimensionMismatch { .. })
    ));
}

/// Stop times that are not sums of the step sizes are hit exactly (bit for bit), never
/// passed, and the integrator continues from them.
#[test]
fn stop_times_are_hit_exactly() {
    let mut s = decay(1.0);
    let mut r = Radau5::new(&mut s, 0.0, &[1.0], opts(1e-8, 1e-12)).unwrap();
    for stop in [0.1, 0.3, 1.0 / 3.0, 0.7, 1.1, 2.9] {
        run(&mut s, &mut r, stop, |_, _| {}).unwrap();
        assert_eq!(
            r.t().to_bits(),
            stop.to_bits(),
            "t = {} for stop {stop}",
            r.t()
        );
        assert!((r.y()[0] - (-stop).exp()).abs() < 1e-8);
    }
    assert!(matches!(
        r.step(&mut s, 2.9),
        Err(RadauError::StopNotAhead { .. })
    ));
    assert!(matches!(
        r.step(&mut s, 1.0),
        Err(RadauError::StopNotAhead { .. })
    ));
}

/// y' = −k y with k switched from 1 to 10 at t = 0.5 (a scheduled event): stop on 0.5,
/// switch, restart, continue. y(1) = e^(−0.5)·e^(−5) within 1e-7 relative; after a second
/// restart that also halves the state, y(1.5) = y(1)/2·e^(−5) likewise.
#[test]
fn restart_after_a_parameter_switch() {
    let k = std::rc::Rc::new(std::cell::Cell::new(1.0));
    let (kf, kj) = (k.clone(), k.clone());
    let mut s = sys(
        1,
        move |_t, y: &[f64], dy: &mut [f64]| dy[0] = -kf.get() * y[0],
        move |_t, _y: &[f64], j: &mut DMatrix<f64>| j[(0, 0)] = -kj.get(),
    );
    let mut r = Radau5::new(&mut s, 0.0, &[1.0], opts(1e-8, 1e-12)).unwrap();
    run(&mut s, &mut r, 0.5, |_, _| {}).unwrap();
    k.set(10.0);
    r.restart(None).unwrap();
    // Only the restart time is valid for interpolation now.
    let mut buf = [0.0];
    r.interpolate(0.5, &mut buf).unwrap();
    assert!(r.interpolate(0.49, &mut buf).is_err());
    let jac_before = r.stats().jacobians;
    run(&mut s, &mut r, 1.0, |_, _| {}).unwrap();
    assert!(r.stats().jacobians > jac_before, "stale Jacobian kept");
    let want = (-0.5f64).exp() * (-5.0f64).exp();
    assert!(
        ((r.y()[0] - want) / want).abs() < 1e-7,
        "{} vs {want}",
        r.y()[0]
    );
    let half = r.y()[0] / 2.0;
    r.restart(Some(&[half])).unwrap();
    run(&mut s, &mut r, 1.5, |_, _| {}).unwrap();
    let want = half * (-5.0f64).exp();
    assert!(
        ((r.y()[0] - want) / want).abs() < 1e-7,
        "{} vs {want}",
        r.y()[0]
    );
    assert!(matches!(
        r.restart(Some(&[f64::NAN])),
        Err(RadauError::NonFinite { .. })
    ));
    assert!(matches!(
        r.restart(Some(&[1.0, 2.0])),
        Err(RadauError::DimensionMismatch { .. })
    ));
}

/// y' = y², y(0) = 1 blows up at t = 1: integrating to t = 2 ends with an error carrying a
/// time within 1e-3 of 1, without panicking and in a bounded number of steps.
#[test]
fn blow_up_ends_with_an_error_near_the_singularity() {
    let mut s = sys(
        1,
        |_t, y: &[f64], dy: &mut [f64]| dy[0] = y[0] * y[0],
        |_t, y: &[f64], j: &mut DMatrix<f64>| j[(0, 0)] = 2.0 * y[0],
    );
    let mut r = Radau5::new(&mut s, 0.0, &[1.0], opts(1e-6, 1e-6)).unwrap();
    let err = run(&mut s, &mut r, 2.0, |_, _| {}).unwrap_err();
    println!("blow-up: {err} ({:?})", r.stats());
    let t = match err {
        RadauError::StepSizeTooSmall { t, .. }
        | RadauError::NewtonDiverged { t, .. }
        | RadauError::NonFinite { t, .. } => t,
        other => panic!("unexpected error {other:?}"),
    };
    assert!((t - 1.0).abs() < 1e-3, "stopped at t = {t}");
    assert!(r.stats().steps < 10_000, "{:?}", r.stats());
}

/// Bad options and inputs are refused with the culprit named.
#[test]
fn bad_inputs_are_refused() {
    let make = |o: RadauOptions, y0: &[f64]| Radau5::new(&mut decay(1.0), 0.0, y0, o).err();
    let e = make(opts(0.0, 1e-6), &[1.0]).unwrap();
    assert!(e.to_string().contains("rtol"), "{e}");
    let e = make(opts(1e-6, -1.0), &[1.0]).unwrap();
    assert!(e.to_string().contains("atol"), "{e}");
    let o = RadauOptions {
        atol: vec![1e-6; 3],
        ..RadauOptions::default()
    };
    assert!(matches!(
        make(o, &[1.0]),
        Some(RadauError::InvalidOption { option: "atol", .. })
    ));
    assert!(matches!(
        make(opts(1e-6, 1e-6), &[1.0, 2.0]),
        Some(RadauError::DimensionMismatch { .. })
    ));
    assert!(matches!(
        make(opts(1e-6, 1e-6), &[f64::INFINITY]),
        Some(RadauError::NonFinite { index: 0, .. })
    ));
    // f(t0, y0) not finite: named at once.
    let mut s = sys(
        1,
        |_t, y: &[f64], dy: &mut [f64]| dy[0] = y[0].ln(),
        |_t, y: &[f64], j: &mut DMatrix<f64>| j[(0, 0)] = 1.0 / y[0],
    );
    let e = Radau5::new(&mut s, 0.0, &[-1.0], opts(1e-6, 1e-6)).unwrap_err();
    assert!(
        matches!(
            e,
            RadauError::NonFinite {
                what: "f(t, y)",
                ..
            }
        ),
        "{e}"
    );
}

/// A Jacobian full of NaN makes every iteration matrix singular: the run ends with
/// `SingularMatrix` at the start time instead of stepping with garbage.
#[test]
fn nan_jacobian_ends_with_singular_matrix() {
    let mut s = sys(
        1,
        |_t, y: &[f64], dy: &mut [f64]| dy[0] = -y[0],
        |_t, _y: &[f64], j: &mut DMatrix<f64>| j[(0, 0)] = f64::NAN,
    );
    let mut r = Radau5::new(&mut s, 0.0, &[1.0], opts(1e-6, 1e-6)).unwrap();
    let e = r.step(&mut s, 1.0).unwrap_err();
    assert!(
        matches!(e, RadauError::SingularMatrix { t, .. } if t == 0.0),
        "{e}"
    );
    assert_eq!(r.stats().singular, 5);
}

/// y' = −√y, y(0) = 1 reaches 0 at t = 2 (y = (1 − t/2)²), and f is NaN for y < 0: Newton
/// iterations that stray below 0 are retried smaller, and the run ends near t = 2 with an
/// error naming f(t, y) (the last accepted state is −2e-14, inside atol = 1e-10, where f is
/// undefined), never with a NaN state.
#[test]
fn rhs_undefined_beyond_a_point_ends_with_an_error_there() {
    let mut s = sys(
        1,
        |_t, y: &[f64], dy: &mut [f64]| dy[0] = -y[0].sqrt(),
        |_t, y: &[f64], j: &mut DMatrix<f64>| j[(0, 0)] = -0.5 / y[0].sqrt(),
    );
    let mut r = Radau5::new(&mut s, 0.0, &[1.0], opts(1e-6, 1e-10)).unwrap();
    let e = run(&mut s, &mut r, 3.0, |r, _| assert!(r.y()[0].is_finite())).unwrap_err();
    println!("sqrt: {e} ({:?})", r.stats());
    let t = match e {
        RadauError::NonFinite { t, .. } | RadauError::NewtonDiverged { t, .. } => t,
        other => panic!("unexpected error {other:?}"),
    };
    assert!((t - 2.0).abs() < 1e-3, "stopped at t = {t}");
    assert!(r.stats().newton_failures > 0, "{:?}", r.stats());
}
