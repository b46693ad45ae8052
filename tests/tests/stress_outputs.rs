//! Stress outputs in `[outputs]` and cross-section declarations: the names
//! `<arm>.link<k>.<quantity>(x=…)` read the arm's stress block, and bad declarations are
//! errors naming the entry, with a hint (docs/stress.md).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bg_model::Model;

fn boom(section: &str, stress_at: &str, outputs: &str) -> String {
    format!(
        r#"
title = "boom"
[elements.arm]
kind = "manipulator.planar_arm"
links = [
  {{ type = "beam", length = 4.0, E = 210e9, rho = 7850.0, A = 0.0264, I = 5.89e-4, modes = 3, {section} }},
]
{stress_at}
[simulation]
t_end = 0.05
dt_out = 0.01
[outputs]
{outputs}
"#
    )
}

const SECTION: &str = "section = { A = 0.0264, I = 5.89e-4, c_top = 0.2, c_bottom = 0.1 }";

fn error_of(text: &str) -> String {
    match Model::from_text("boom.toml", text, &bg_sim::registry(), &[]) {
        Ok(_) => panic!("the model loads"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn stress_outputs_read_the_block_and_sigma_follows_navier() {
    let text = boom(
        SECTION,
        "stress_at = [{ link = 1, x = 1.5 }]",
        "N = \"arm.link1.N(x=1.50)\"\nM = \"arm.link1.M(x=1.5)\"\nst = \"arm.link1.sigma_top(x=1.5)\"\nsb = \"arm_stress.link1.sigma_bottom(x=1.5)\"",
    );
    let mut m = Model::from_text("boom.toml", &text, &bg_sim::registry(), &[])
        .unwrap_or_else(|e| panic!("{e}"));
    let out = m.run().unwrap();
    let c = |n: &str| out.trajectory.column(n).unwrap();
    let (n, mm, st, sb) = (c("N"), c("M"), c("st"), c("sb"));
    let (a, i) = (0.0264, 5.89e-4);
    for r in 0..n.len() {
        let want_top = n[r] / a - mm[r] * 0.2 / i;
        let want_bottom = n[r] / a + mm[r] * 0.1 / i;
        assert!((st[r] - want_top).abs() <= 1e-9 * want_top.abs().max(1.0));
        assert!((sb[r] - want_bottom).abs() <= 1e-9 * want_bottom.abs().max(1.0));
    }
    // the boom swings down on its hinge: a moment of some size
    assert!(mm.iter().any(|v| v.abs() > 100.0), "{mm:?}");
}

#[test]
fn stress_output_of_an_undeclared_section_is_an_error_with_a_hint() {
    let text = boom(
        SECTION,
        "stress_at = [{ link = 1, x = 1.5 }]",
        "M = \"arm.link1.M(x=2.0)\"",
    );
    let e = error_of(&text);
    assert!(
        e.contains("arm_stress.link1.M(x=2)") && e.contains("stress_at"),
        "{e}"
    );
}

#[test]
fn stress_bad_sections_are_errors_naming_the_link() {
    let e = error_of(&boom(
        "section = { A = 0.0264, I = 5.89e-4, c_top = 0.2 }",
        "",
        "q = \"arm_arm.q1\"",
    ));
    assert!(e.contains("links[1].section"), "{e}");
    let e = error_of(&boom(
        "section = { A = 0.0264, I = 5.89e-4, c_top = 0.2, c_bottom = -0.1 }",
        "",
        "q = \"arm_arm.q1\"",
    ));
    assert!(e.contains("c_bottom"), "{e}");
    let e = error_of(&boom(
        SECTION,
        "stress_at = [{ link = 1, x = 5.0 }]",
        "q = \"arm_arm.q1\"",
    ));
    assert!(e.contains("x = 5"), "{e}");
}
