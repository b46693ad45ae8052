//! The cost of one right-hand-side evaluation of a model: `cargo run --release -p bg-sim
//! --example rhs_cost -- models/knuckle_boom.toml`. Loads the model, then times loops of
//! `StateEquations::rhs` at states along a short straight path from the initial state (so
//! that no cache keyed by the state hits), and of `evaluate` (every stage, outputs too).
//! Prints the median of several loops in µs per call.

use std::path::PathBuf;
use std::time::Instant;

use bg_model::Model;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), String> {
    let path = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "models/knuckle_boom.toml".into()),
    );
    let model = Model::load(&path, &bg_sim::registry(), &[]).map_err(|e| e.to_string())?;
    let eqs = &model.equations;
    let n = eqs.n_states();
    let x0 = model.x0.clone();
    let mut dx = vec![0.0; n];
    eqs.rhs(0.0, &x0, &mut dx);
    // A direction of change: the state derivative at x0, scaled to small steps.
    let dir: Vec<f64> = dx.iter().map(|d| d * 1e-6).collect();
    let states: Vec<Vec<f64>> = (0..256)
        .map(|k| x0.iter().zip(&dir).map(|(x, d)| x + k as f64 * d).collect())
        .collect();
    let time = |f: &mut dyn FnMut(&[f64])| -> f64 {
        let reps = 40;
        let loops: Vec<f64> = (0..15)
            .map(|_| {
                let t = Instant::now();
                for _ in 0..reps {
                    for x in &states {
                        f(x);
                    }
                }
                t.elapsed().as_secs_f64() * 1e6 / (reps * states.len()) as f64
            })
            .collect();
        median(loops)
    };
    let rhs = time(&mut |x| eqs.rhs(0.1, x, &mut dx));
    let all = time(&mut |x| eqs.evaluate(0.1, x));
    println!("{}: {n} states", path.display());
    println!("rhs:      {rhs:.3} µs per call (median of 15 loops of 10 240 calls)");
    println!("evaluate: {all:.3} µs per call (every stage, outputs included)");
    Ok(())
}
