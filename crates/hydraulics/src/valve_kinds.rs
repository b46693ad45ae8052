//! Model-file builders of the valve kinds (`docs/hydraulics.md`, "Valves"): how each reads
//! its parameters. Errors point at the offending key.

use bg_model::{ElementSpec, ErrorKind, ModelError, Registry};
use bondgraph::Element;

use crate::kinds::{alpha, boolean, boxed};
use crate::{
    Centre, CheckValve, CounterbalanceValve, DirectionalValve, FlowControlValve, PilotCheckValve,
    PressureReducingValve, ReliefValve, SequenceValve, Valve22, Valve32,
};

type Built = Result<Box<dyn Element>, ModelError>;

/// Register the valve kinds.
pub fn register(r: &mut Registry) {
    r.register(
        "hydraulics.relief_valve",
        "relief valve P → T: x = ramp((Δp − p_crack)/dp_override), Q = α·x·regRoot(Δp); optional poppet lag tau",
        relief,
    );
    r.register(
        "hydraulics.check_valve",
        "check valve in → out: x = ramp((Δp − p_crack)/dp_open), Q = α·x·regRoot(Δp) + g_leak·Δp",
        check,
    );
    r.register(
        "hydraulics.pilot_check_valve",
        "pilot-operated check in → out, pilot X: x = ramp((Δp + ratio·P_X − p_crack)/dp_open)",
        pilot_check,
    );
    r.register(
        "hydraulics.counterbalance_valve",
        "counterbalance valve V, C, pilot X: opens C → V when P_C + ratio·P_X ≥ p_set; free flow V → C through a check",
        counterbalance,
    );
    r.register(
        "hydraulics.sequence_valve",
        "sequence valve P → A: opens when P_P ≥ p_crack (spring chamber drained)",
        sequence,
    );
    r.register(
        "hydraulics.pressure_reducing_valve",
        "pressure-reducing valve P → A: x = ramp((p_set − P_A)/dp_band)",
        reducing,
    );
    r.register(
        "hydraulics.directional_valve",
        "4/3 directional valve, ports P, T, A, B: spool x_v ∈ [−1, 1], centre closed/open/tandem/float, overlap/underlap",
        directional,
    );
    r.register(
        "hydraulics.valve_2_2",
        "2/2 valve P → A: opening u ∈ [0, 1] (or 1 − u normally open)",
        |s| {
            let v = Valve22::new(
                alpha(s)?,
                s.param("u", "command signal in [0, 1]")?,
                boolean(s, "normally_open", false)?,
                s.number_or("g_leak", 0.0)?,
                s.number_or("p_tr", 1e5)?,
            );
            boxed(s, v)
        },
    );
    r.register(
        "hydraulics.valve_3_2",
        "3/2 valve, ports P, A, T: u = 0 A → T, u = 1 P → A",
        |s| {
            let v = Valve32::new(
                alpha(s)?,
                s.param("u", "command signal in [0, 1]")?,
                boolean(s, "normally_open", false)?,
                s.number_or("g_leak", 0.0)?,
                s.number_or("p_tr", 1e5)?,
            );
            boxed(s, v)
        },
    );
    r.register(
        "hydraulics.flow_control_valve",
        "pressure-compensated flow control P → A: Q = q_set once Δp ≥ dp_comp, the metering orifice below",
        |s| {
            let v = FlowControlValve::new(
                s.param("q_set", "set flow, m³/s")?,
                s.number("dp_comp", "compensator pressure, Pa")?,
                s.number_or("smoothing", 0.05)?,
                s.number_or("g_leak", 0.0)?,
                s.number_or("p_tr", 1e5)?,
            );
            boxed(s, v)
        },
    );
}

fn relief(s: &ElementSpec<'_>) -> Built {
    let mut v = ReliefValve::new(alpha(s)?, s.number("p_crack", "cracking pressure, Pa")?);
    v.dp_override = s.number_or("dp_override", v.dp_override)?;
    v.smoothing = s.number_or("smoothing", v.smoothing)?;
    v.g_leak = s.number_or("g_leak", v.g_leak)?;
    v.p_tr = s.number_or("p_tr", v.p_tr)?;
    if s.has("tau") {
        v.tau = Some(s.number("tau", "poppet time constant, s")?);
    }
    boxed(s, v.build())
}

fn check(s: &ElementSpec<'_>) -> Built {
    let mut v = CheckValve::new(alpha(s)?);
    v.p_crack = s.number_or("p_crack", v.p_crack)?;
    v.dp_open = s.number_or("dp_open", v.dp_open)?;
    v.smoothing = s.number_or("smoothing", v.smoothing)?;
    v.g_leak = s.number_or("g_leak", v.g_leak)?;
    v.p_tr = s.number_or("p_tr", v.p_tr)?;
    boxed(s, v.build())
}

fn pilot_check(s: &ElementSpec<'_>) -> Built {
    let mut v = PilotCheckValve::new(alpha(s)?);
    v.ratio = s.number_or("ratio", v.ratio)?;
    v.p_crack = s.number_or("p_crack", v.p_crack)?;
    v.dp_open = s.number_or("dp_open", v.dp_open)?;
    v.smoothing = s.number_or("smoothing", v.smoothing)?;
    v.g_leak = s.number_or("g_leak", v.g_leak)?;
    v.p_tr = s.number_or("p_tr", v.p_tr)?;
    boxed(s, v.build())
}

fn counterbalance(s: &ElementSpec<'_>) -> Built {
    let mut v = CounterbalanceValve::new(alpha(s)?, s.number("p_set", "setting, Pa")?);
    v.ratio = s.number_or("ratio", v.ratio)?;
    v.dp_open = s.number_or("dp_open", v.dp_open)?;
    v.alpha_check = s.number_or("alpha_check", v.alpha_check)?;
    v.p_check = s.number_or("p_check", v.p_check)?;
    v.dp_check = s.number_or("dp_check", v.dp_check)?;
    v.smoothing = s.number_or("smoothing", v.smoothing)?;
    v.g_leak = s.number_or("g_leak", v.g_leak)?;
    v.p_tr = s.number_or("p_tr", v.p_tr)?;
    boxed(s, v.build())
}

fn sequence(s: &ElementSpec<'_>) -> Built {
    let mut v = SequenceValve::new(alpha(s)?, s.number("p_crack", "opening pressure, Pa")?);
    v.dp_override = s.number_or("dp_override", v.dp_override)?;
    v.smoothing = s.number_or("smoothing", v.smoothing)?;
    v.g_leak = s.number_or("g_leak", v.g_leak)?;
    v.p_tr = s.number_or("p_tr", v.p_tr)?;
    boxed(s, v.build())
}

fn reducing(s: &ElementSpec<'_>) -> Built {
    let mut v =
        PressureReducingValve::new(alpha(s)?, s.number("p_set", "outlet pressure setting, Pa")?);
    v.dp_band = s.number_or("dp_band", v.dp_band)?;
    v.smoothing = s.number_or("smoothing", v.smoothing)?;
    v.g_leak = s.number_or("g_leak", v.g_leak)?;
    v.p_tr = s.number_or("p_tr", v.p_tr)?;
    boxed(s, v.build())
}

fn directional(s: &ElementSpec<'_>) -> Built {
    let word = s.string_or("centre", "closed")?;
    let Some(centre) = Centre::from_word(&word) else {
        return Err(s.error(
            "centre",
            ErrorKind::BadParameter,
            format!(
                "(hydraulics.directional_valve) `centre` must be \"closed\", \"open\", \"tandem\" or \"float\", not \"{word}\""
            ),
        ));
    };
    let (overlap, underlap) = (s.number_or("overlap", 0.0)?, s.number_or("underlap", 0.0)?);
    let (area, stroke) = (
        s.number_or("centre_area", 1.0)?,
        s.number_or("centre_stroke", 0.2)?,
    );
    let (g_leak, p_tr) = (s.number_or("g_leak", 1e-13)?, s.number_or("p_tr", 1e5)?);
    let v = DirectionalValve::new(alpha(s)?, s.param("x_v", "spool stroke signal")?)
        .and_then(|v| v.with_lap(overlap, underlap))
        .and_then(|v| v.with_centre(centre, area, stroke))
        .and_then(|v| v.with_leakage(g_leak, p_tr));
    boxed(s, v)
}
