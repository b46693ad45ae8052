//! The cost of one exact Jacobian in right-hand-side evaluations, for a model file:
//! `cargo run --release -p bg-sim --example jacobian_cost -- models/knuckle_boom.toml`.
//!
//! Times `rhs` and `jacobian` over many calls at slightly different states (so that no
//! element's cache answers) and prints the medians of several rounds and their ratio.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use bondgraph::DMatrix;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "models/knuckle_boom.toml".into());
    let model = bg_model::Model::load(path.as_ref(), &bg_sim::registry(), &[])
        .unwrap_or_else(|e| panic!("{e}"));
    let eqs = &model.equations;
    let n = eqs.n_states();
    let x0 = eqs.initial_state();
    let nominal: Vec<f64> = eqs.states().iter().map(|s| s.nominal).collect();
    let states: Vec<Vec<f64>> = (0..16)
        .map(|k| {
            x0.iter()
                .zip(&nominal)
                .enumerate()
                .map(|(j, (x, s))| x + 1e-3 * s * ((j * 7 + k * 13) as f64).sin())
                .collect()
        })
        .collect();
    let mut dx = vec![0.0; n];
    let mut jac = DMatrix::zeros(n, n);
    let (calls_rhs, calls_jac) = (4000, 400);
    let (mut t_rhs, mut t_jac) = (Vec::new(), Vec::new());
    for _ in 0..7 {
        let start = Instant::now();
        for k in 0..calls_rhs {
            eqs.rhs(0.0, &states[k % states.len()], &mut dx);
        }
        t_rhs.push(start.elapsed().as_secs_f64() / calls_rhs as f64);
        let start = Instant::now();
        for k in 0..calls_jac {
            eqs.jacobian(0.0, &states[k % states.len()], &mut jac);
        }
        t_jac.push(start.elapsed().as_secs_f64() / calls_jac as f64);
    }
    let (r, j) = (median(t_rhs), median(t_jac));
    println!(
        "{path}: {n} states; rhs {:.2} µs, Jacobian {:.2} µs = {:.1} rhs (finite differences: {} rhs)",
        r * 1e6,
        j * 1e6,
        j / r,
        n + 1
    );
}
