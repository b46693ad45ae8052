//! The Jacobian of every model, bit for bit as the chain rule of commit 3f8d2e4 computed it.
//!
//! The Jacobian feeds the LU of the implicit steppers: any change of the order in which the
//! chain rule sums its products changes the crane's step sequence. Each Jacobian (dense, and
//! the sparse values on the pattern) is reduced to a 64-bit FNV-1a hash of its entries' bits
//! and compared with `tests/data/jacobian_bits.txt`, written by the algorithm before the
//! compiled constant partials (`BG_BLESS_JACOBIAN_BITS=1` writes the file again).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fmt::Write as _;

use bg_tests::{is_refused, model_files, root};
use bondgraph::{DMatrix, StateEquations};

/// FNV-1a over the bits of `values`.
fn hash(values: impl Iterator<Item = f64>) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325_u64;
    for v in values {
        for b in v.to_bits().to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// One line per evaluation point: the dense and the sparse Jacobian's hashes.
fn lines(name: &str, eqs: &StateEquations, out: &mut String) {
    if eqs.n_states() == 0 {
        return;
    }
    let x0 = eqs.initial_state();
    let pattern = eqs.jacobian_pattern().unwrap();
    let mut jac = DMatrix::zeros(0, 0);
    let mut values = vec![0.0; pattern.nnz()];
    for k in 0..4 {
        // the initial state, then deterministic perturbations of a few per cent
        let x: Vec<f64> = x0
            .iter()
            .zip(eqs.states())
            .enumerate()
            .map(|(j, (x, s))| {
                let d = 0.02 * s.nominal * ((j * 7 + k * 13) as f64).sin();
                if k == 0 {
                    *x
                } else {
                    x + d
                }
            })
            .collect();
        let t = 0.1 * k as f64;
        eqs.jacobian(t, &x, &mut jac);
        eqs.jacobian_sparse(t, &x, &pattern, &mut values);
        let dense = hash(jac.iter().copied());
        let sparse = hash(values.iter().copied());
        writeln!(out, "{name} {k} {dense:016x} {sparse:016x}").unwrap();
    }
}

#[test]
fn jacobian_of_every_model_is_bit_identical_to_the_stored_one() {
    let mut now = String::new();
    for path in model_files().into_iter().filter(|p| !is_refused(p)) {
        let Ok(model) = bg_model::Model::load(&path, &bg_sim::registry(), &[]) else {
            continue;
        };
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        lines(&name, &model.equations, &mut now);
    }
    lines(
        "every_kind",
        &bg_tests::every_kind().unwrap().equations,
        &mut now,
    );
    let mut crane = bg_tests::load("knuckle_boom", &["simulation.t_end=0.05"]).unwrap();
    let out = crane.run().unwrap();
    let mut jac = DMatrix::zeros(0, 0);
    crane
        .equations
        .jacobian(out.t_final, &out.x_final, &mut jac);
    writeln!(now, "knuckle_boom_run 0 {:016x}", hash(jac.iter().copied())).unwrap();

    let file = root().join("tests/data/jacobian_bits.txt");
    if std::env::var_os("BG_BLESS_JACOBIAN_BITS").is_some() {
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(&file, &now).unwrap();
    }
    let stored = std::fs::read_to_string(&file).unwrap();
    let (mut checked, mut differ) = (0, Vec::new());
    for (a, b) in now.lines().zip(stored.lines()) {
        checked += 1;
        if a != b {
            differ.push(format!("now {a}, stored {b}"));
        }
    }
    assert_eq!(
        now.lines().count(),
        stored.lines().count(),
        "models or points changed"
    );
    assert!(
        differ.is_empty(),
        "{} Jacobians moved:\n{}",
        differ.len(),
        differ.join("\n")
    );
    assert!(checked >= 20, "only {checked} Jacobians compared");
}
