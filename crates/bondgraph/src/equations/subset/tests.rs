#![allow(clippy::unwrap_used, clippy::float_cmp)]

use super::*;

/// The mass–spring–damper driven by the input `F`: every probe it has, at a state away
/// from rest.
fn msd() -> (StateEquations, Vec<Probe>, Vec<f64>) {
    let eqs = crate::test_models::msd(1.5, 0.02, 0.7, 0.0, Some(3.0));
    let probes = eqs
        .probe_names()
        .iter()
        .map(|n| eqs.probe(n).unwrap())
        .collect();
    (eqs, probes, vec![0.4, -0.03])
}

fn whole(eqs: &StateEquations, p: Probe, t: f64, x: &[f64]) -> f64 {
    eqs.evaluate(t, x);
    eqs.read(p, t, x)
}

fn only(eqs: &StateEquations, s: &Subset, p: Probe, t: f64, x: &[f64]) -> f64 {
    eqs.forget();
    eqs.evaluate_only(s, t, x);
    eqs.read(p, t, x)
}

#[test]
fn every_probe_reads_as_after_a_whole_evaluation() {
    let (eqs, probes, x) = msd();
    for &p in &probes {
        let s = eqs.subset(&[p]);
        let (want, got) = (whole(&eqs, p, 0.2, &x), only(&eqs, &s, p, 0.2, &x));
        assert!(want.is_finite(), "{p:?} = {want}");
        assert_eq!(got.to_bits(), want.to_bits(), "{p:?}");
    }
}

#[test]
fn leaving_out_any_needed_stage_shows() {
    // dp/dt of the mass reads every stage of the plan: each one left out makes it NaN.
    let (eqs, _, x) = msd();
    let p = Probe::Derivative(0);
    let s = eqs.subset(&[p]);
    assert_eq!(s.n_stages(), eqs.order.len());
    assert_eq!(s.n_derivatives(), 1);
    for k in 0..s.stages.len() {
        let mut short = s.clone();
        short.stages.remove(k);
        let got = only(&eqs, &short, p, 0.2, &x);
        assert!(got.is_nan(), "without stage {:?}: {got}", s.stages[k]);
    }
    let mut short = s.clone();
    short.derivatives.clear();
    assert!(only(&eqs, &short, p, 0.2, &x).is_nan());
}

#[test]
fn only_what_is_read_runs() {
    let (eqs, _, x) = msd();
    // Time and states need no stage.
    let s = eqs.subset(&[Probe::Time, Probe::State(0), Probe::State(1)]);
    assert_eq!((s.n_stages(), s.n_derivatives()), (0, 0));
    // The spring's effort q/C: its one stage, nothing else (the mass's flow stays unknown).
    let e = eqs.probe("spring.e").unwrap();
    let s = eqs.subset(&[e]);
    assert_eq!((s.n_stages(), s.n_derivatives()), (1, 0));
    assert!((only(&eqs, &s, e, 0.0, &x) + 1.5).abs() < 1e-12);
    assert!(eqs.read(eqs.probe("mass.f").unwrap(), 0.0, &x).is_nan());
}

#[test]
fn the_flat_steps_are_the_plan() {
    // `steps`, `rhs_steps` and `owners` call what `order`, `rhs_order` and the layouts say,
    // each with a copy of its element's layout.
    let (eqs, probes, _) = msd();
    let calls = |s: &[Step]| s.iter().map(|c| (c.id, c.stage)).collect::<Vec<_>>();
    assert_eq!(calls(&eqs.steps), eqs.order);
    assert_eq!(calls(&eqs.rhs_steps), eqs.rhs_order);
    let owners: Vec<_> = (0..eqs.layouts.len())
        .filter(|&id| eqs.layouts[id].n_states > 0)
        .map(|id| (id, 0))
        .collect();
    assert_eq!(calls(&eqs.owners), owners);
    assert_eq!(eqs.owners.len(), 2);
    for c in eqs.steps.iter().chain(&eqs.owners) {
        let l = &eqs.layouts[c.id];
        let ports = |l: &crate::element::Layout| {
            let p = l.ports.iter().map(|p| (p.offset, p.dim, p.sign.to_bits()));
            p.collect::<Vec<_>>()
        };
        assert_eq!(ports(&c.layout), ports(l));
        assert_eq!(c.layout.outputs, l.outputs);
        assert_eq!(c.layout.inputs.len(), l.inputs.len());
        assert_eq!(
            (c.layout.state_offset, c.layout.n_states),
            (l.state_offset, l.n_states)
        );
    }
    // Subsets compare by the calls they make.
    let all = eqs.subset(&probes);
    assert_eq!(all, eqs.subset(&probes));
    assert_ne!(all, eqs.subset(&[Probe::Derivative(0)]));
    assert_ne!(all, Subset::default());
}
