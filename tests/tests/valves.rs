//! The valve kinds conserve volume and only dissipate: at random port pressures, spool
//! strokes and commands, built from model text as a user would write them, the flows into
//! every valve sum to zero (to 1e-12 of the flow through it) and the power into it,
//! Σ P·Q, is ≥ 0 (to −1e-12 of Σ |P·Q|).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use proptest::prelude::*;

/// Each kind with its ports (in order) and its parameters; `X` in the text is the spool
/// stroke or command, drawn at random.
const VALVES: &[(&str, &[&str], &str)] = &[
    (
        "hydraulics.relief_valve",
        &["P", "T"],
        "alpha = 2e-7, p_crack = 1e7",
    ),
    ("hydraulics.check_valve", &["in", "out"], "alpha = 1e-6"),
    (
        "hydraulics.pilot_check_valve",
        &["in", "out", "X"],
        "alpha = 1e-6, ratio = 4.0",
    ),
    (
        "hydraulics.counterbalance_valve",
        &["V", "C", "X"],
        "alpha = 6e-7, p_set = 1.1e7, ratio = 3.0",
    ),
    (
        "hydraulics.sequence_valve",
        &["P", "A"],
        "alpha = 1e-6, p_crack = 8e6",
    ),
    (
        "hydraulics.pressure_reducing_valve",
        &["P", "A"],
        "alpha = 1e-6, p_set = 5e6",
    ),
    (
        "hydraulics.directional_valve",
        &["P", "T", "A", "B"],
        "alpha = 6e-7, x_v = X, centre = \"open\", overlap = 0.05",
    ),
    (
        "hydraulics.directional_valve",
        &["P", "T", "A", "B"],
        "alpha = 6e-7, x_v = X, centre = \"float\", underlap = 0.05",
    ),
    (
        "hydraulics.directional_valve",
        &["P", "T", "A", "B"],
        "alpha = 6e-7, x_v = X, centre = \"tandem\"",
    ),
    (
        "hydraulics.valve_2_2",
        &["P", "A"],
        "alpha = 1e-6, u = X, g_leak = 1e-13",
    ),
    (
        "hydraulics.valve_3_2",
        &["P", "A", "T"],
        "alpha = 1e-6, u = X, g_leak = 1e-13",
    ),
    (
        "hydraulics.flow_control_valve",
        &["P", "A"],
        "q_set = X, dp_comp = 1e6, g_leak = 1e-13",
    ),
    // the load-sensing network (docs/hydraulics.md, "Load sensing")
    (
        "hydraulics.shuttle_valve",
        &["a", "b", "out"],
        "alpha = 5e-7",
    ),
    (
        "hydraulics.ls_section",
        &["P", "T", "A", "B", "LS"],
        "q_nom = 6e-4, x_v = X",
    ),
    (
        "hydraulics.ls_section",
        &["P", "T", "A", "B", "LS", "X"],
        "q_nom = 6e-4, x_v = X, compensator = \"post\", dp_comp = 1e5",
    ),
    // the fixed restrictions obey the same two laws
    ("hydraulics.laminar", &["a", "b"], "length = 2.0, d = 0.012"),
    (
        "hydraulics.orifice",
        &["a", "b"],
        "alpha = 1e-6, opening = \"0.5 + 0.5*sin(t)\"",
    ),
    ("hydraulics.leakage", &["a", "b"], "r = 1e11"),
];

fn model(kind: &str, ports: &[&str], params: &str, p: &[f64], x: f64) -> String {
    let mut text = String::from("title = \"valve at random pressures\"\n[elements]\n");
    text += &format!(
        "v = {{ kind = \"{kind}\", {} }}\n",
        params.replace('X', &format!("{x:e}"))
    );
    for (k, pk) in p.iter().enumerate().take(ports.len()) {
        text += &format!("s{k} = {{ kind = \"Se\", e = {pk:e} }}\n");
    }
    text += "[bonds]\n";
    for (k, port) in ports.iter().enumerate() {
        text += &format!("b{k} = \"s{k} -> v.{port}\"\n");
    }
    text
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn valves_conserve_volume_and_dissipate(
        p in proptest::collection::vec(-1e6f64..3e7, 6),
        x in -1.2f64..1.2,
    ) {
        for (kind, ports, params) in VALVES {
            // a command in [0, 1] is drawn from the same x; a set flow scaled to m³/s
            let x = match *kind {
                "hydraulics.flow_control_valve" => x * 1e-3,
                _ => x,
            };
            let text = model(kind, ports, params, &p, x);
            let m = bg_model::Model::from_text("valve", &text, &bg_sim::registry(), &[])
                .unwrap_or_else(|e| panic!("{kind}: {e}\n{text}"));
            let eqs = &m.equations;
            let x0 = eqs.initial_state();
            eqs.evaluate(0.0, &x0);
            let g = eqs.graph();
            let id = (0..g.n_elements()).find(|&i| g.node(i).name == "v").unwrap();
            let power = eqs.power_into(id);
            let scale = eqs.power_scale(id);
            prop_assert!(power >= -1e-12 * scale, "{kind} {params} at {p:?}, {x}: power {power:e} of {scale:e}");
            let flows: Vec<f64> = (0..ports.len())
                .map(|k| eqs.read(eqs.probe(&format!("b{k}.f")).unwrap(), 0.0, &x0))
                .collect();
            let through: f64 = flows.iter().map(|q| q.abs()).sum();
            let sum: f64 = flows.iter().sum();
            prop_assert!(sum.abs() <= 1e-12 * through, "{kind} at {p:?}, {x}: flows {flows:?}");
            // the pilot ports pass nothing
            if let Some(k) = ports.iter().position(|p| *p == "X") {
                prop_assert!(flows[k] == 0.0, "{kind}: pilot flow {}", flows[k]);
            }
        }
    }
}

/// `models/lift_circuit.toml` with one replacement.
fn lift_circuit_with(from: &str, to: &str) -> Result<bg_model::Model, bg_model::ModelError> {
    let text = std::fs::read_to_string(bg_tests::root().join("models/lift_circuit.toml")).unwrap();
    assert!(text.contains(from), "{from}");
    bg_model::Model::from_text(
        "lift_circuit.toml",
        &text.replacen(from, to, 1),
        &bg_sim::registry(),
        &[],
    )
}

/// Bad valve parameters are refused naming the element and the key, never a panic.
#[test]
fn bad_valve_parameters_name_the_element_and_key() {
    let cases = [
        // missing, misspelt, out of range, unknown word, excluding each other, wrong unit
        (r#", p_crack = "p_relief""#, "", "relief", "p_crack"),
        (r#"p_set = "p_cbv""#, r#"p_sett = "p_cbv""#, "cbv", "p_set"),
        (r#"centre = "open""#, r#"centre = "opne""#, "dcv", "centre"),
        (
            r#"centre_stroke = 0.6"#,
            "centre_stroke = 1.5",
            "dcv",
            "centre_stroke",
        ),
        (
            r#"centre_stroke = 0.6"#,
            "centre_stroke = 0.6, overlap = 0.1, underlap = 0.1",
            "dcv",
            "underlap",
        ),
        (r#"ratio = "ratio""#, "ratio = -1.0", "cbv", "ratio"),
        (
            r#"alpha = 1e-6 }"#,
            "alpha = 1e-6, smoothing = 0.7 }",
            "check",
            "smoothing",
        ),
        (
            r#"p_crack = "p_relief""#,
            r#"p_crack = "16 m""#,
            "relief",
            "p_crack",
        ),
    ];
    for (from, to, element, key) in cases {
        let e = lift_circuit_with(from, to).unwrap_err();
        assert_eq!(e.element.as_deref(), Some(element), "{from} → {to}: {e}");
        assert!(e.to_string().contains(key), "{from} → {to}: {e}");
    }
    // and a value with a unit is read in SI: 160 bar is the file's 16 MPa
    assert!(lift_circuit_with(r#"p_crack = "p_relief""#, r#"p_crack = "160 bar""#).is_ok());
}
