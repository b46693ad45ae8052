//! Write a model's exact Jacobian to a text file, for benchmarking linear algebra on it:
//! `cargo run --release -p bg-sim --example dump_jacobian -- models/knuckle_boom.toml
//! /tmp/jac.txt [key=value ...]`.
//!
//! The file holds n on its first line, then several Jacobians (at the initial state and at
//! slightly perturbed states, so that entries that vanish at rest show up), each as n lines
//! of n numbers (row i, columns 0..n). Prints the count of structural non-zeros.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fmt::Write as _;

use bondgraph::DMatrix;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .unwrap_or_else(|| "models/knuckle_boom.toml".into());
    let out = args.next().unwrap_or_else(|| "/tmp/jac.txt".into());
    let overrides: Vec<String> = args.collect();
    let model = bg_model::Model::load(path.as_ref(), &bg_sim::registry(), &overrides)
        .unwrap_or_else(|e| panic!("{e}"));
    let eqs = &model.equations;
    let n = eqs.n_states();
    let x0 = eqs.initial_state();
    let nominal: Vec<f64> = eqs.states().iter().map(|s| s.nominal).collect();
    let mut jac = DMatrix::zeros(n, n);
    let mut text = format!("{n}\n");
    let mut pattern = vec![false; n * n];
    for k in 0..4 {
        let x: Vec<f64> = x0
            .iter()
            .zip(&nominal)
            .enumerate()
            .map(|(j, (x, s))| {
                let d = if k == 0 {
                    0.0
                } else {
                    1e-2 * s * ((j * 7 + k * 13) as f64).sin()
                };
                x + d
            })
            .collect();
        eqs.jacobian(0.1 * k as f64, &x, &mut jac);
        for i in 0..n {
            for j in 0..n {
                let v = jac[(i, j)];
                if v != 0.0 {
                    pattern[j * n + i] = true;
                }
                write!(text, "{v:e} ").unwrap();
            }
            text.push('\n');
        }
    }
    std::fs::write(&out, text).unwrap();
    let nnz = pattern.iter().filter(|&&p| p).count();
    println!(
        "{path}: n = {n}, {nnz} structural non-zeros of {} -> {out}",
        n * n
    );
    for i in 0..n {
        let row: String = (0..n)
            .map(|j| if pattern[j * n + i] { 'x' } else { '.' })
            .collect();
        println!("{row}  {}", eqs.states()[i].name);
    }
}
