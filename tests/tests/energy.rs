//! The energy audit (`bondgraph::energy`, issue 26): on every model in `models/`, what the
//! sources supplied equals what the storages gained plus what the dissipative elements turned
//! into heat, to 1e-6 of the energy that moved at rtol 1e-8; the conservative elements
//! (junctions, TF, GY, MTF) lose nothing.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_tests::{is_refused, model_files};
use bondgraph::EnergyRole;

#[test]
fn every_model_closes_its_energy_balance() {
    let mut ran = 0;
    let only = std::env::var("BG_ENERGY_ONLY").unwrap_or_default();
    let rtol: f64 = std::env::var("BG_ENERGY_RTOL")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1e-8);
    for path in model_files().into_iter().filter(|p| !is_refused(p)) {
        if !path.display().to_string().contains(&only) {
            continue;
        }
        let mut model = bg_model::Model::load(&path, &bg_sim::registry(), &[])
            .unwrap_or_else(|e| panic!("{e}"));
        model.settings.rtol = rtol;
        model.settings.atol = model.settings.atol.min(1e-10);
        let run = model.energy().unwrap();
        assert!(
            run.outcome.error.is_none(),
            "{}: {:?}",
            path.display(),
            run.outcome.error
        );
        let r = &run.report;
        eprintln!(
            "{}: supplied {:.6e} stored {:.6e} dissipated {:.6e} residual {:.3e} (relative {:.3e} of {:.3e}), conservative {:.3e}, {} steps",
            path.display(),
            r.supplied,
            r.stored,
            r.dissipated,
            r.residual,
            r.relative_residual(),
            r.reference,
            r.conservative,
            r.steps
        );
        for e in &r.elements {
            eprintln!(
                "    {:<28} {:<26} {:<12} net {:>13.6e} act {:>12.6e} through {:>12.6e} fn {}",
                e.name,
                e.kind,
                e.role.name(),
                e.net,
                e.activity,
                e.through,
                e.stored_by_function
            );
        }
        assert!(
            r.relative_residual() <= 1e-6,
            "{}: the balance does not close: {:e}",
            path.display(),
            r.relative_residual()
        );
        for e in r
            .elements
            .iter()
            .filter(|e| e.role == EnergyRole::Conservative)
        {
            assert!(
                e.net.abs() <= 1e-6 * e.through.max(1e-12 * r.reference),
                "{}: `{}` ({}) should conserve power but lost {:e} J of {:e} J through it",
                path.display(),
                e.name,
                e.kind,
                e.net,
                e.through
            );
        }
        ran += 1;
    }
    assert!(
        ran >= 5,
        "expected at least five runnable models, found {ran}"
    );
}
