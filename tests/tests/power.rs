//! Power conservation: at random states of every example, the power into every junction,
//! TF, GY and MTF is zero to 1e-12 of the power through it.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_tests::{is_refused, model_files};
use proptest::prelude::*;

const CONSERVATIVE: &[&str] = &["0", "1", "TF", "MTF", "GY", "MGY"];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn junctions_and_transformers_conserve_power(seed in proptest::collection::vec(-1.0f64..1.0, 64), t in 0.0f64..10.0) {
        let mut checked = 0;
        for path in model_files().into_iter().filter(|p| !is_refused(p)) {
            let model = bg_model::Model::load(&path, &bg_sim::registry(), &[]).unwrap();
            let eqs = &model.equations;
            // Random states around each state's scale.
            let x: Vec<f64> = eqs.states().iter().enumerate().map(|(i, s)| {
                let scale = s.initial.abs().max(s.nominal);
                seed[i % seed.len()] * scale * (1.0 + i as f64)
            }).collect();
            eqs.evaluate(t, &x);
            let g = eqs.graph();
            for id in 0..g.n_elements() {
                let kind = g.node(id).element.kind();
                if CONSERVATIVE.contains(&kind) {
                    let p = eqs.power_into(id);
                    let scale = eqs.power_scale(id);
                    prop_assert!(p.abs() <= 1e-12 * scale.max(f64::MIN_POSITIVE), "{}: {} ({kind}) takes {p:e} W of {scale:e}", path.display(), g.node(id).name);
                    checked += 1;
                }
            }
        }
        prop_assert!(checked >= 10);
    }
}
