//! `StateEquations::jacobian` against central differences of `rhs`, for every model in
//! `models/` that loads and has states, at the initial state, at perturbed states, and for the
//! crane after a short run.
//!
//! The norm: each column is scaled by its state's nominal magnitude (the change of fᵢ for a
//! nominal change of xⱼ), and every entry must satisfy
//!
//! ```text
//! |Jᵢⱼ − J_fd,ᵢⱼ|·nomⱼ ≤ 1e-6·(|J_fd,ᵢⱼ|·nomⱼ + maxₖ |J_fd,ᵢₖ|·nomₖ)
//! ```
//!
//! At a kink of the equations (a clamp, a valve's switch of side at x_v = 0), where the
//! right and left differences disagree, the entry may equal either one-sided derivative.
#![allow(clippy::float_cmp, clippy::unwrap_used, clippy::expect_used)]

use bg_tests::{is_refused, model_files};
use bondgraph::{DMatrix, StateEquations};

const TOL: f64 = 1e-6;

/// Central, forward and backward differences of `rhs` at (t, x), column by column.
fn differences(eqs: &StateEquations, t: f64, x: &[f64]) -> [DMatrix<f64>; 3] {
    let n = x.len();
    let mut out = [
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
    ];
    let (mut f0, mut fp, mut fm) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    eqs.rhs(t, x, &mut f0);
    let mut xp = x.to_vec();
    for j in 0..n {
        let scale = x[j].abs().max(eqs.states()[j].nominal);
        let h = (x[j] + 6e-6 * scale) - x[j];
        xp[j] = x[j] + h;
        eqs.rhs(t, &xp, &mut fp);
        xp[j] = x[j] - h;
        eqs.rhs(t, &xp, &mut fm);
        xp[j] = x[j];
        // one-sided differences with a smaller step, for kinks
        let h1 = (x[j] + 1e-8 * scale) - x[j];
        let (mut f1p, mut f1m) = (vec![0.0; n], vec![0.0; n]);
        xp[j] = x[j] + h1;
        eqs.rhs(t, &xp, &mut f1p);
        xp[j] = x[j] - h1;
        eqs.rhs(t, &xp, &mut f1m);
        xp[j] = x[j];
        for i in 0..n {
            out[0][(i, j)] = (fp[i] - fm[i]) / (2.0 * h);
            out[1][(i, j)] = (f1p[i] - f0[i]) / h1;
            out[2][(i, j)] = (f0[i] - f1m[i]) / h1;
        }
    }
    out
}

/// Compare at (t, x); returns the worst entry as (ratio of error to allowance, i, j).
fn compare(name: &str, eqs: &StateEquations, t: f64, x: &[f64]) -> (f64, usize, usize) {
    let n = x.len();
    let mut jac = DMatrix::zeros(0, 0);
    eqs.jacobian(t, x, &mut jac);
    // The sparse path: its pattern holds every nonzero of the dense Jacobian, and its values
    // are the dense ones, bit for bit (so it agrees with the differences as the dense does).
    let pattern = eqs.jacobian_pattern().unwrap();
    let mut values = vec![f64::NAN; pattern.nnz()];
    eqs.jacobian_sparse(t, x, &pattern, &mut values);
    for j in 0..n {
        for i in 0..n {
            match pattern.slot(i, j) {
                Some(k) => assert!(
                    values[k] == jac[(i, j)],
                    "{name} at t = {t}: sparse J[{i}][{j}] = {:e}, dense {:e}",
                    values[k],
                    jac[(i, j)]
                ),
                None => assert!(
                    jac[(i, j)] == 0.0,
                    "{name} at t = {t}: J[{i}][{j}] ({} / {}) = {:e} lies outside the sparsity pattern",
                    eqs.states()[i].name,
                    eqs.states()[j].name,
                    jac[(i, j)]
                ),
            }
        }
    }
    let [jc, jr, jl] = differences(eqs, t, x);
    let nom: Vec<f64> = eqs.states().iter().map(|s| s.nominal).collect();
    let mut worst = (0.0, 0, 0);
    for i in 0..n {
        let row = (0..n)
            .map(|k| jc[(i, k)].abs() * nom[k])
            .fold(0.0, f64::max);
        for j in 0..n {
            let allow = TOL * (jc[(i, j)].abs() * nom[j] + row);
            let err = |r: &DMatrix<f64>| (jac[(i, j)] - r[(i, j)]).abs() * nom[j];
            let mut e = err(&jc);
            // a kink: the one-sided differences disagree by more than the tolerance
            if (jr[(i, j)] - jl[(i, j)]).abs() * nom[j] > allow {
                e = e.min(err(&jr)).min(err(&jl));
            }
            let ratio = if allow > 0.0 {
                e / allow
            } else if e == 0.0 {
                0.0
            } else {
                f64::INFINITY
            };
            assert!(
                ratio <= 1.0,
                "{name} at t = {t}: J[{i}][{j}] ({} / {}) = {:e}, central differences {:e} (right {:e}, left {:e}); allowance {allow:e}",
                eqs.states()[i].name,
                eqs.states()[j].name,
                jac[(i, j)],
                jc[(i, j)],
                jr[(i, j)],
                jl[(i, j)],
            );
            if ratio > worst.0 {
                worst = (ratio, i, j);
            }
        }
    }
    worst
}

/// Deterministic perturbations of a few per cent of each state's nominal size.
fn perturbed(eqs: &StateEquations, x0: &[f64], k: usize) -> Vec<f64> {
    x0.iter()
        .zip(eqs.states())
        .enumerate()
        .map(|(j, (x, s))| x + 0.02 * s.nominal * ((j * 7 + k * 13) as f64).sin())
        .collect()
}

fn check_model(path: &std::path::Path) -> Option<f64> {
    let model = bg_model::Model::load(path, &bg_sim::registry(), &[]).ok()?;
    let name = path.file_stem()?.to_string_lossy().into_owned();
    check_equations(&name, &model.equations)
}

fn check_equations(name: &str, eqs: &StateEquations) -> Option<f64> {
    if eqs.n_states() == 0 {
        return None;
    }
    let name = name.to_owned();
    let x0 = eqs.initial_state();
    let mut worst = compare(&name, eqs, 0.0, &x0);
    for k in 1..=3 {
        let x = perturbed(eqs, &x0, k);
        let w = compare(&name, eqs, 0.1 * k as f64, &x);
        if w.0 > worst.0 {
            worst = w;
        }
    }
    eprintln!(
        "{name}: worst entry J[{}][{}] ({} / {}) at {:.1e} of the allowance",
        worst.1,
        worst.2,
        eqs.states()[worst.1].name,
        eqs.states()[worst.2].name,
        worst.0
    );
    Some(worst.0)
}

#[test]
fn jacobian_matches_central_differences_for_every_model() {
    let mut checked = 0;
    for path in model_files().into_iter().filter(|p| !is_refused(p)) {
        if check_model(&path).is_some() {
            checked += 1;
        }
    }
    assert!(checked >= 5, "only {checked} models checked");
}

#[test]
fn jacobian_matches_central_differences_for_every_element_kind() {
    let model = bg_tests::every_kind().unwrap();
    assert!(check_equations("every_kind", &model.equations).is_some());
}

#[test]
fn crane_jacobian_matches_central_differences_after_a_short_run() {
    let mut model = bg_tests::load("knuckle_boom", &["simulation.t_end=0.05"]).unwrap();
    let out = model.run().unwrap();
    assert!(out.error.is_none(), "{:?}", out.error);
    let t = out.t_final;
    let w = compare("knuckle_boom", &model.equations, t, &out.x_final);
    eprintln!(
        "knuckle_boom after {t} s: worst at {:.1e} of the allowance",
        w.0
    );
}

/// The load-sensing circuit with its spools open: one section metering under a rising load
/// (2.5 s), both in saturation (6.5 s), the cut-off holding a stalled load (9.5 s) — the
/// pump's controller, the compensators (pre and post), the shuttles and the LS edges active.
/// The lines' cavitation is switched off: a motor line held at the vapour pressure sits on
/// the fluid law's steep knee, where central differences lose digits (`hydraulics.chamber`'s
/// own tests check that law); the LS kinds are what is checked here.
#[test]
fn ls_circuit_jacobian_matches_central_differences_mid_run() {
    let mut sets: Vec<String> = Vec::new();
    for c in ["pre", "post"] {
        for k in 1..=2 {
            for v in ["hose_a", "hose_b", "vol_ls"] {
                sets.push(format!("elements.{v}{k}_{c}.cavitation=false"));
            }
        }
    }
    for t_end in ["2.5", "6.5", "9.5"] {
        let mut set: Vec<&str> = sets.iter().map(String::as_str).collect();
        let end = format!("simulation.t_end={t_end}");
        set.push(&end);
        let mut model = bg_tests::load("ls_circuit", &set).unwrap();
        let out = model.run().unwrap();
        assert!(out.error.is_none(), "{:?}", out.error);
        let t = out.t_final;
        let w = compare("ls_circuit", &model.equations, t, &out.x_final);
        eprintln!(
            "ls_circuit at {t} s: worst entry J[{}][{}] at {:.1e} of the allowance",
            w.1, w.2, w.0
        );
    }
}

#[test]
fn crane_with_geometric_stiffening_jacobian_matches_central_differences() {
    // the axial shortening of the bent booms (`elements.crane.geometric_stiffening`), at the
    // initial state, perturbed states, and after a short run
    let mut model = bg_tests::load(
        "knuckle_boom",
        &[
            "elements.crane.geometric_stiffening=true",
            "simulation.t_end=0.05",
        ],
    )
    .unwrap();
    let worst = check_equations("knuckle_boom (stiffening)", &model.equations).unwrap();
    assert!(worst <= 1.0, "{worst}");
    let out = model.run().unwrap();
    assert!(out.error.is_none(), "{:?}", out.error);
    let w = compare(
        "knuckle_boom (stiffening)",
        &model.equations,
        out.t_final,
        &out.x_final,
    );
    eprintln!(
        "knuckle_boom with stiffening after {} s: worst at {:.1e} of the allowance",
        out.t_final, w.0
    );
}
