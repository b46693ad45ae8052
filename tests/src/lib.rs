//! Helpers for the workspace tests: where the models are, and how to load them with every
//! element kind the CLI knows.

use std::path::PathBuf;

use bg_model::{Model, ModelError};

/// The workspace root.
#[must_use]
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every `models/*.toml`, sorted.
#[must_use]
pub fn model_files() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("models"))
        .map(|d| {
            d.filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Models that are meant to be refused (their file name says so).
#[must_use]
pub fn is_refused(path: &std::path::Path) -> bool {
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    name == "derivative_causality" || name == "algebraic_loop"
}

/// Load `models/<name>.toml` with `--set` overrides.
pub fn load(name: &str, overrides: &[&str]) -> Result<Model, ModelError> {
    let set: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    Model::load(
        &root().join("models").join(format!("{name}.toml")),
        &bg_sim::registry(),
        &set,
    )
}

/// A model with every core and hydraulics element kind that the files in `models/` leave
/// out (and many they use), modulated by states, signals and time, for the Jacobian and
/// allocation tests. Not meant to be physical.
pub const EVERY_KIND: &str = r#"
title = "Every core and hydraulics kind"

[elements]
src   = { kind = "Sf", f = "0.1*sin(t) + 0.01*m1.p" }
j0    = { kind = "0" }
c1    = { kind = "C", k = 100.0, q0 = 0.02 }
r1    = { kind = "R", r = "2 + 10*c1.q^2" }
gy    = { kind = "MGY", r = "1 + 0.5*c1.q" }
c3    = { kind = "C", c = 0.2, q0 = -0.01 }
j1    = { kind = "1" }
m1    = { kind = "I", m = 1.5, p0 = 0.3 }
r2    = { kind = "R", r = 0.4 }
se    = { kind = "Se", e = "sin(t) + 0.2*c2.q" }
tf    = { kind = "TF", m = 2.0 }
c2    = { kind = "C", c = 0.05, q0 = 0.01 }
m2    = { kind = "I", m = 2.0, p0 = [0.1, -0.2] }
mtf   = { kind = "MTF", T = [["1 + 0.1*c1.q"], ["0.5"]] }
c4    = { kind = "C", c = 0.1, q0 = 0.03 }
sig   = { kind = "signal", value = "0.5*sin(t) + c1.q" }
lg    = { kind = "lag", input = "sig.out", tau = 0.1, y0 = 0.05 }
pc    = { kind = "p_control", input = "lg.out", gain = 3.0, setpoint = "0.1*c2.q", min = -1.0, max = 1.0 }
ch    = { kind = "hydraulics.chamber", volume = 1e-3, beta = 1.5e9, p0 = 5e6 }
jl    = { kind = "0" }
ori   = { kind = "hydraulics.orifice", alpha = 1e-6, opening = "0.5 + 0.4*pc.out", p_tr = 1e5 }
tank  = { kind = "Se", e = 0.0 }
leak  = { kind = "hydraulics.tank_leakage", r = 1e12 }
sump  = { kind = "Se", e = 0.0 }
pmp   = { kind = "hydraulics.pump", displacement = 1e-6, speed = "100 + 10*sin(t)", fraction = "0.5 + 0.3*pc.out", c_l = 1e-12, t_c = 1.0, b = 1e-3 }
mot   = { kind = "hydraulics.motor", displacement = 2e-6, fraction = "0.8 + 0.1*sin(t)", c_l = 1e-12, t_c = 0.5, t_s = 0.8, omega_s = 1.0, b = 1e-3 }
drn   = { kind = "Se", e = 0.0 }
jm    = { kind = "1" }
rot   = { kind = "I", m = 1e-3, p0 = 0.01 }
fr    = { kind = "hydraulics.friction", f_c = 0.2, f_s = 0.3, v_s = 1.0, v_tanh = 0.1, b = 1e-3 }

[bonds]
b1 = "src -> j0"
b2 = "j0 -> c1"
b3 = "j0 -> r1"
b4 = "j0 -> gy.1"
b5 = "gy.2 -> c3"
b6 = "se -> j1"
b7 = "j1 -> m1"
b8 = "j1 -> r2"
b9 = "j1 -> tf.1"
b10 = "tf.2 -> c2"
b11 = "m2 -> mtf.1"
b12 = "mtf.2 -> c4"
b13 = "jl -> ch"
b14 = "jl -> ori.a"
b15 = "ori.b -> tank"
b16 = "jl -> leak"
b17 = "sump -> pmp.a"
b18 = "pmp.b -> jl"
b19 = "jl -> mot.a"
b20 = "mot.b -> drn"
b21 = "mot.shaft -> jm"
b22 = "jm -> rot"
b23 = "jm -> fr"

[simulation]
t_end = 0.1
"#;

/// [`EVERY_KIND`], loaded.
pub fn every_kind() -> Result<Model, ModelError> {
    Model::from_text("every_kind.toml", EVERY_KIND, &bg_sim::registry(), &[])
}
