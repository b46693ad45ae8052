//! `[scene]`: switches are read, exposed on `Model::scene`, turned into `--set` overrides, and
//! every mistake is refused at load time with its line and a hint.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::{ErrorKind, Model, Registry};

const BASE: &str = r#"
[parameters]
k = 100.0
m = 1.0

[elements]
v      = { kind = "1" }
mass   = { kind = "I", m = "m" }
spring = { kind = "C", k = "k", q0 = 0.01 }

[bonds]
b1 = "v -> mass"
b2 = "v -> spring"
"#;

fn load(scene: &str) -> Result<Model, bg_model::ModelError> {
    Model::from_text(
        "s.toml",
        &format!("{BASE}\n[scene]\n{scene}\n"),
        &Registry::with_core(),
        &[],
    )
}

/// The line of `[scene]`'s first switch in the texts of `load`.
fn first_switch_line() -> usize {
    BASE.lines().count() + 3
}

#[test]
fn switches_are_read_in_order_with_their_overrides() {
    let m = load(
        "stiff = { set = \"parameters.k\", choices = [1e6, 100.0, 1] }\n\
         mass = { set = \"elements.mass.m\", choices = [\"2*m\", \"m\"], also = { m = [\"parameters.k=50\"] } }",
    )
    .unwrap();
    let s = &m.scene;
    assert_eq!(s.switches.len(), 2);
    assert_eq!(s.grid_size(), 6);
    let stiff = &s.switches[0];
    assert_eq!(stiff.name, "stiff");
    assert_eq!(stiff.line, first_switch_line());
    let labels: Vec<&str> = stiff.choices.iter().map(|c| c.label.as_str()).collect();
    assert_eq!(labels, ["1e6", "100.0", "1"]);
    assert_eq!(
        s.overrides(&[0, 1]),
        [
            "parameters.k=1e6",
            "elements.mass.m=\"m\"",
            "parameters.k=50"
        ]
    );
    assert_eq!(s.describe(&[2, 0]), "stiff=1 mass=2*m");
    // each scene loads with its overrides
    for pick in [[0, 0], [2, 1]] {
        let over = s.overrides(&pick);
        let text = format!(
            "{BASE}\n[scene]\nstiff = {{ set = \"parameters.k\", choices = [1e6, 100.0, 1] }}\n"
        );
        let m = Model::from_text("s.toml", &text, &Registry::with_core(), &over).unwrap();
        assert!(m.parameters["k"] > 0.0);
    }
    // a model without [scene] has none
    let plain = Model::from_text("p.toml", BASE, &Registry::with_core(), &[]).unwrap();
    assert!(plain.scene.is_empty());
    assert_eq!(plain.scene.grid_size(), 1);
}

#[test]
fn mistakes_are_refused_with_line_and_hint() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "a = { set = \"parameters.k\", choices = [1, 2], default = 1 }",
            "unknown key `default`",
            "set, choices and also",
        ),
        (
            "a = { set = \"parameters.k\", choices = [] }",
            "`choices` is empty",
            "richest",
        ),
        ("a = { choices = [1] }", "has no `set`", "richest"),
        (
            "a = { set = \"parameters.kk\", choices = [1, 2] }",
            "no parameter `kk`",
            "parameters are: k, m",
        ),
        (
            "a = { set = \"elements.nothing.m\", choices = [1] }",
            "no element `nothing`",
            "it has: v, mass, spring",
        ),
        (
            "a = { set = \"simulation.t_stop\", choices = [1] }",
            "has no key `t_stop`",
            "t_end",
        ),
        (
            "a = { set = \"parameters.k\", choices = [1, 1] }",
            "listed twice",
            "",
        ),
        (
            "a = { set = \"parameters.k\", choices = [1, 2], also = { 3 = [\"parameters.m=2\"] } }",
            "not a choice",
            "the choices are: 1, 2",
        ),
        (
            "a = { set = \"parameters.k\", choices = [1, 2], also = { 2 = [\"parameters.q=2\"] } }",
            "no parameter `q`",
            "",
        ),
        (
            "a = { set = \"parameters.k\", choices = [[1]] }",
            "must be a number, a string or a boolean",
            "",
        ),
        ("a = 3", "must be a table", "choices"),
        (
            "a = { set = \"scene.b\", choices = [1] }",
            "cannot change [scene]",
            "",
        ),
    ];
    for (scene, message, hint) in cases {
        let e = load(scene).expect_err(scene);
        assert_eq!(e.kind, ErrorKind::Scene, "{scene}: {e}");
        assert_eq!(e.line, Some(first_switch_line()), "{scene}: {e}");
        let text = e.to_string();
        assert!(text.contains("[scene] `a`"), "{scene}: {text}");
        assert!(text.contains(message), "{scene}: {text}");
        assert!(
            hint.is_empty() || e.hint.as_deref().is_some_and(|h| h.contains(hint)),
            "{scene}: {text}"
        );
    }
}

#[test]
fn the_crane_and_the_lift_declare_their_switches() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models");
    for (file, names) in [
        ("knuckle_boom.toml", &["modes1", "modes2", "lumped"][..]),
        ("cylinder_lift.toml", &["p_tr", "leakage"][..]),
    ] {
        let text = std::fs::read_to_string(root.join(file)).unwrap();
        // parse only: [scene] needs no element kinds beyond the file's, so read it through
        // the TOML and check the names and the richest-first order here
        let doc: toml::Table = text.parse().unwrap();
        let scene = doc["scene"].as_table().unwrap();
        let keys: Vec<&str> = scene.keys().map(String::as_str).collect();
        assert_eq!(keys, names, "{file}");
    }
}
