//! Evaluating only what is read (`StateEquations::subset`, `evaluate_only`): for every model
//! in `models/` and the every-kind model, at the start and at perturbed states, the probes
//! read bit for bit as after a whole evaluation — every probe alone, the output columns
//! together, and the columns the model's checks read. Before each subset evaluation every
//! value is forgotten (NaN), so a stage the subset left out shows as a NaN or a changed bit.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_tests::{is_refused, model_files};
use bondgraph::{Probe, StateEquations};

/// Deterministic perturbations of a few per cent of each state's nominal size.
fn perturbed(eqs: &StateEquations, x0: &[f64], k: usize) -> Vec<f64> {
    x0.iter()
        .zip(eqs.states())
        .enumerate()
        .map(|(j, (x, s))| x + 0.02 * s.nominal * ((j * 7 + k * 13) as f64).sin())
        .collect()
}

/// Compare `probes` read after a subset evaluation with a whole one at (t, x).
fn compare(name: &str, eqs: &StateEquations, probes: &[Probe], t: f64, x: &[f64]) {
    let subset = eqs.subset(probes);
    eqs.evaluate(t, x);
    let want: Vec<f64> = probes.iter().map(|&p| eqs.read(p, t, x)).collect();
    eqs.forget();
    eqs.evaluate_only(&subset, t, x);
    for (&p, w) in probes.iter().zip(&want) {
        let got = eqs.read(p, t, x);
        assert!(
            got.to_bits() == w.to_bits(),
            "{name} at t = {t}: {p:?} reads {got:e} after its {} stages, {w:e} after all",
            subset.n_stages()
        );
    }
}

fn check(name: &str, model: &bg_model::Model) -> usize {
    let eqs = &model.equations;
    let every: Vec<Probe> = eqs
        .probe_names()
        .iter()
        .map(|n| eqs.probe(n).unwrap())
        .collect();
    let outputs: Vec<Probe> = model.outputs.iter().map(|o| o.probe).collect();
    let checked: Vec<Probe> = model
        .outputs
        .iter()
        .filter(|o| {
            model
                .checks
                .iter()
                .any(|c| c.value.contains(&o.name) || c.expected.contains(&o.name))
        })
        .map(|o| o.probe)
        .collect();
    let x0 = model.x0.clone();
    for (k, t) in [(0, 0.0), (1, 0.3), (2, 1.1)] {
        let x = if k == 0 {
            x0.clone()
        } else {
            perturbed(eqs, &x0, k)
        };
        for &p in &every {
            compare(name, eqs, &[p], t, &x);
        }
        compare(name, eqs, &outputs, t, &x);
        compare(name, eqs, &checked, t, &x);
    }
    let all = eqs.subset(&every);
    let rows = eqs.subset(&outputs);
    let checks = eqs.subset(&checked);
    eprintln!(
        "{name}: {} probes; stages: {} for all, {} for the {} outputs, {} for the {} checked columns",
        every.len(),
        all.n_stages(),
        rows.n_stages(),
        outputs.len(),
        checks.n_stages(),
        checked.len()
    );
    every.len()
}

#[test]
fn subsets_read_as_whole_evaluations_for_every_model() {
    let mut checked = 0;
    for path in model_files().into_iter().filter(|p| !is_refused(p)) {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let model = bg_model::Model::load(&path, &bg_sim::registry(), &[])
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(check(&name, &model) > 0);
        checked += 1;
    }
    assert!(checked >= 10, "only {checked} models checked");
}

#[test]
fn subsets_read_as_whole_evaluations_for_every_element_kind() {
    let model = bg_tests::every_kind().unwrap();
    assert!(check("every_kind", &model) > 0);
}
