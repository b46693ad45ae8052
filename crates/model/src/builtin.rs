//! Builders for the core element kinds.
//!
//! | kind | parameters |
//! |---|---|
//! | `Se` | `e` effort (may be modulated) |
//! | `Sf` | `f` flow delivered (may be modulated) |
//! | `R` | `r` resistance (may be modulated) |
//! | `C` | `c` compliance or `k` stiffness (may be modulated); `q0` initial displacement (number or array: multibond) |
//! | `I` | `m` inertance (may be modulated); `p0` initial momentum or `v0` initial flow (number or array) |
//! | `TF` | `m` modulus (constant) |
//! | `MTF` | `m` modulus expression, or `T` matrix of expressions (e₁ = T·e₂) |
//! | `GY`, `MGY` | `r` modulus (constant / may be modulated) |
//! | `0`, `1` | none |
//! | `lag` | `input` signal, `tau` time constant, `y0` initial output |
//! | `p_control` | `input` signal, `gain`, `setpoint` (may be modulated), `min`, `max` |
//! | `signal` | `value` expression of `t`, parameters and signals |

use bondgraph::element::SignalSpec;
use bondgraph::{
    Capacitor, EffortSource, Element, FlowSource, Gyrator, Inertia, Lag, MatrixTransformer,
    OneJunction, PController, Param, Resistor, SignalFunction, Transformer, ZeroJunction,
};

use crate::error::{ErrorKind, ModelError};
use crate::registry::{ElementSpec, Registry};

type Built = Result<Box<dyn Element>, ModelError>;

pub(crate) fn register(r: &mut Registry) {
    r.register("Se", "effort source: e = e(t, signals)", se);
    r.register("Sf", "flow source: delivers f = f(t, signals)", sf);
    r.register("R", "resistor: e = r·f", resistor);
    r.register("C", "capacitor: dq/dt = f, e = q/c (or k·q)", capacitor);
    r.register("I", "inertia: dp/dt = e, f = p/m", inertia);
    r.register("TF", "transformer: e1 = m·e2, f2 = m·f1", tf);
    r.register(
        "MTF",
        "modulated transformer: e1 = m(signals)·e2, or e1 = T(signals)·e2 on multibonds",
        mtf,
    );
    r.register("GY", "gyrator: e1 = r·f2, e2 = r·f1", gy);
    r.register("MGY", "modulated gyrator: r = r(signals)", gy);
    r.register("0", "0-junction: common effort, flows sum to zero", |_| {
        Ok(Box::new(ZeroJunction))
    });
    r.register("1", "1-junction: common flow, efforts sum to zero", |_| {
        Ok(Box::new(OneJunction))
    });
    r.register(
        "lag",
        "signal block: tau·dy/dt = input − y, output `<name>.out`",
        lag,
    );
    r.register(
        "p_control",
        "signal block: out = clamp(gain·(setpoint − input), min, max)",
        p_control,
    );
    r.register(
        "signal",
        "signal block: out = value(t, parameters, signals)",
        signal,
    );
}

fn se(s: &ElementSpec<'_>) -> Built {
    Ok(Box::new(EffortSource::new(s.param("e", "effort")?)))
}

fn sf(s: &ElementSpec<'_>) -> Built {
    Ok(Box::new(FlowSource::new(s.param("f", "flow delivered")?)))
}

fn resistor(s: &ElementSpec<'_>) -> Built {
    Resistor::new(s.param("r", "resistance")?)
        .map(|e| Box::new(e) as _)
        .map_err(|e| s.param_error(&e))
}

fn capacitor(s: &ElementSpec<'_>) -> Built {
    let c = match (s.has("c"), s.has("k")) {
        (true, false) => s.param("c", "compliance")?,
        (false, true) => match s.param("k", "stiffness")? {
            Param::Const(k) if k.is_finite() && k > 0.0 => Param::Const(1.0 / k),
            Param::Const(k) => {
                return Err(s.error(
                    "k",
                    ErrorKind::BadParameter,
                    format!("(C) parameter `k` = {k} is invalid: it must be finite and > 0"),
                ));
            }
            Param::Modulated { inputs, law } => {
                Param::modulated(inputs, move |t, u| 1.0 / law(t, u))
            }
        },
        (true, true) => {
            return Err(s.error(
                "k",
                ErrorKind::BadParameter,
                "(C) give either `c` (compliance) or `k` (stiffness), not both",
            ))
        }
        (false, false) => {
            return Err(s
                .error(
                    "c",
                    ErrorKind::MissingParameter,
                    "(C) needs `c` (compliance) or `k` (stiffness)",
                )
                .hint(format!("add `c = …` or `k = …` to element `{}`", s.name)))
        }
    };
    let q0 = s.vector_or("q0", vec![0.0])?;
    Capacitor::multi(c, q0)
        .map(|e| Box::new(e) as _)
        .map_err(|e| s.param_error(&e))
}

fn inertia(s: &ElementSpec<'_>) -> Built {
    let m = s.param("m", "inertance (mass)")?;
    let p0 = if s.has("v0") {
        if s.has("p0") {
            return Err(s.error(
                "v0",
                ErrorKind::BadParameter,
                "(I) give either `p0` (momentum) or `v0` (flow), not both",
            ));
        }
        let Some(mass) = m.constant() else {
            return Err(s.error(
                "v0",
                ErrorKind::BadParameter,
                "(I) `v0` needs a constant `m`; give `p0` instead",
            ));
        };
        s.vector_or("v0", vec![0.0])?
            .into_iter()
            .map(|v| mass * v)
            .collect()
    } else {
        s.vector_or("p0", vec![0.0])?
    };
    Inertia::multi(m, p0)
        .map(|e| Box::new(e) as _)
        .map_err(|e| s.param_error(&e))
}

fn tf(s: &ElementSpec<'_>) -> Built {
    let m = s.number("m", "modulus")?;
    Transformer::new(m)
        .map(|e| Box::new(e) as _)
        .map_err(|e| s.param_error(&e))
}

fn mtf(s: &ElementSpec<'_>) -> Built {
    if s.has("T") {
        if s.has("m") {
            return Err(s.error(
                "m",
                ErrorKind::BadParameter,
                "(MTF) give either `m` (scalar) or `T` (matrix), not both",
            ));
        }
        let (n1, n2, inputs, entries) = s.matrix("T", "modulus matrix")?;
        let specs = inputs.iter().map(|n| SignalSpec::scalar(n)).collect();
        let n_in = inputs.len();
        let law = Box::new(
            move |io: &bondgraph::Io<'_>, t: &mut nalgebra::DMatrix<f64>| {
                let mut u = [0.0; bondgraph::element::MAX_PARAM_INPUTS];
                for (k, v) in u.iter_mut().take(n_in).enumerate() {
                    *v = io.u(k);
                }
                for i in 0..n1 {
                    for j in 0..n2 {
                        t[(i, j)] = entries[i * n2 + j].eval(&u[..n_in]);
                    }
                }
            },
        );
        return MatrixTransformer::new(n1, n2, specs, law)
            .map(|e| Box::new(e) as _)
            .map_err(|e| s.param_error(&e));
    }
    Transformer::new(s.param("m", "modulus")?)
        .map(|e| Box::new(e) as _)
        .map_err(|e| s.param_error(&e))
}

fn gy(s: &ElementSpec<'_>) -> Built {
    let r = if s.kind == "GY" {
        Param::Const(s.number("r", "modulus")?)
    } else {
        s.param("r", "modulus")?
    };
    Gyrator::new(r)
        .map(|e| Box::new(e) as _)
        .map_err(|e| s.param_error(&e))
}

fn lag(s: &ElementSpec<'_>) -> Built {
    let input = s.signal("input", "signal to follow")?;
    Lag::new(
        &input,
        s.number("tau", "time constant")?,
        s.number_or("y0", 0.0)?,
    )
    .map(|e| Box::new(e) as _)
    .map_err(|e| s.param_error(&e))
}

fn p_control(s: &ElementSpec<'_>) -> Built {
    let input = s.signal("input", "measured signal")?;
    let gain = s.number("gain", "proportional gain")?;
    let setpoint = s.param("setpoint", "set-point")?;
    let lo = s.number_or("min", f64::NEG_INFINITY)?;
    let hi = s.number_or("max", f64::INFINITY)?;
    PController::new(&input, gain, setpoint, lo, hi)
        .map(|e| Box::new(e) as _)
        .map_err(|e| s.param_error(&e))
}

fn signal(s: &ElementSpec<'_>) -> Built {
    Ok(Box::new(SignalFunction::new(
        s.param("value", "expression")?,
    )))
}
