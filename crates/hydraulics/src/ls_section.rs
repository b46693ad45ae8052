//! Compensated valve section `hydraulics.ls_section`: a proportional, closed-centre 4/3
//! section of a load-sensing valve bank, ports `P`, `T`, `A`, `B` and `LS`, with a
//! pressure compensator that is either ahead of the spool (**pre**, individual compensator:
//! the flow follows the spool whatever the load) or behind it (**post**, flow sharing: every
//! section's flow scales down together when the pump cannot supply them all).
//!
//! The spool stroke x ∈ [−1, 1] (a signal, clamped; zero lap) opens the meter-in edge P→A and
//! the meter-out edge B→T for x > 0 (P→B and A→T for x < 0) with opening o = |x|, each with
//! the coefficient α = q_nom/regRoot(Δp_nom) of a datasheet's nominal flow at the nominal
//! spool drop. With W the working port fed (A for x > 0) and `pos(Δ) = regRoot(Δ)` for Δ > 0,
//! 0 otherwise (the compensator closes against reverse flow: it is the section's load-holding
//! check):
//!
//! ```text
//! pre:   Q_PW = α·o·pos(Δp_c·sat((P_P − P_W)/Δp_c))   the compensator holds the spool's drop
//!                                                      at Δp_c: Q_PW = q_nom·o·regRoot(Δp_c)/regRoot(Δp_nom)
//!                                                      while P_P − P_W ≥ Δp_c, the bare spool below
//! post:  Q_PW = α·o·pos(P_P − P_c),  P_c = smax(P_X + Δp_s, P_W)
//!                                                      the compensator behind the spool holds the
//!                                                      spool's outlet at the LS pressure (the highest
//!                                                      load) plus its spring, so every open section
//!                                                      sees the same spool drop P_P − P_LS − Δp_s
//! meter-out: Q_WT = α·o·regRoot(P_W' − P_T)            (W' the other working port)
//! ```
//!
//! `sat` is the rounded knee of `hydraulics.flow_control_valve` (half-width `smoothing`), and
//! `smax` the smooth maximum of [`crate::shuttle_valve::smooth_max`] with width
//! δ = smoothing·Δp_s. Pre: the spool's flow is load-independent while the pump supplies
//! more than Δp_c above the load; when the pump saturates, the section with the lightest
//! load still takes its set flow and the heavier ones starve. Post: Q_i = α·o_i·regRoot(Δp)
//! with one Δp for all, so the flows stay in the ratio of the openings whatever the pump
//! delivers (the flow-sharing, LUDV, principle).
//!
//! The **LS port** senses the working port when the spool is open and drains to tank when it
//! is centred, through small edges of coefficient α_LS: `W → LS` with opening
//! s = clamp(|x|/x_LS, 0, 1), and `LS → T` with 1 − s. Every edge also leaks `g_leak·Δp`
//! (P→A, P→B, A→T, B→T). The flows into the section sum to zero (volume), and each edge's
//! flow has the sign of its drop (Σ P·Q ≥ 0, dissipated). Spool dynamics: with `tau` (a
//! datasheet's spool time constant) the stroke is a state `x`, τ·dx/dt = clamp(x_v) − x;
//! without it the stroke is x_v itself (feed it from the core's `lag` for any other law).
//!
//! A post-compensated section has a sixth port, `X`: the LS gallery's pressure (the LS line
//! after the shuttles, the highest load) that loads its compensator; it passes no flow. Its
//! own `LS` port feeds the shuttle network, like a pre-compensated section's.
//!
//! Causality: conductance at every port (a 0-junction with a volume at each).

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params, Range};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage, StateSpec,
};

use crate::orifice::{reg_root, reg_root_derivative};
use crate::ramp::ramp;
use crate::shuttle_valve::smooth_max;

const P: usize = 0;
const T: usize = 1;
const A: usize = 2;
const B: usize = 3;
const LS: usize = 4;
const X: usize = 5;

/// Where the section's pressure compensator sits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compensator {
    /// Ahead of the spool: holds the spool's drop (individual compensator).
    Pre,
    /// Behind the spool, loaded by the LS pressure: flow sharing.
    Post,
}

/// One edge's flow and its partials over the five port pressures and the spool stroke.
#[derive(Clone, Copy, Debug, Default)]
struct EdgeFlow {
    from: usize,
    to: usize,
    q: f64,
    dq: [f64; 6],
    dx: f64,
}

/// A compensated 4/3 section (see the module documentation).
#[derive(Debug)]
pub struct LsSection {
    compensator: Compensator,
    alpha: f64,
    x_v: Param,
    tau: Option<f64>,
    dp_comp: f64,
    eps: f64,
    alpha_ls: f64,
    x_ls: f64,
    g_leak: f64,
    p_tr: f64,
}

impl LsSection {
    /// A section passing `q_nom` (m³/s) at full stroke and spool drop `dp_nom` (Pa), spool
    /// `x_v`, compensator `compensator` with pressure `dp_comp` (pre: the spool drop held;
    /// post: the spring over the LS pressure), knee `smoothing` ∈ [0, 0.5].
    pub fn new(
        compensator: Compensator,
        q_nom: f64,
        dp_nom: f64,
        x_v: impl Into<Param>,
        dp_comp: f64,
        smoothing: f64,
        p_tr: f64,
    ) -> Result<Self, ParamError> {
        ParamError::positive("q_nom", q_nom)?;
        ParamError::positive("dp_nom", dp_nom)?;
        ParamError::positive("dp_comp", dp_comp)?;
        ParamError::non_negative("p_tr", p_tr)?;
        if !(0.0..=0.5).contains(&smoothing) {
            return Err(ParamError::OutOfRange {
                param: "smoothing".into(),
                value: smoothing,
                requirement: "between 0 and 0.5",
            });
        }
        let x_v = x_v.into();
        if let Some(x) = x_v.constant() {
            ParamError::finite("x_v", x)?;
        }
        Ok(Self {
            compensator,
            alpha: q_nom / reg_root(dp_nom, p_tr),
            x_v,
            tau: None,
            dp_comp,
            eps: smoothing,
            alpha_ls: 5e-7,
            x_ls: 0.05,
            g_leak: 1e-13,
            p_tr,
        })
    }

    /// The LS edges' coefficient α_LS (m³/(s·√Pa), > 0) and the stroke x_LS ∈ (0, 1] at which
    /// the W → LS edge is fully open.
    pub fn with_ls_edges(mut self, alpha_ls: f64, x_ls: f64) -> Result<Self, ParamError> {
        self.alpha_ls = ParamError::positive("alpha_ls", alpha_ls)?;
        if !(x_ls > 0.0 && x_ls <= 1.0) {
            return Err(ParamError::OutOfRange {
                param: "ls_stroke".into(),
                value: x_ls,
                requirement: "in (0, 1]",
            });
        }
        self.x_ls = x_ls;
        Ok(self)
    }

    /// A first-order spool of time constant `tau` (s, > 0): the stroke becomes a state `x`
    /// with τ·dx/dt = clamp(x_v, −1, 1) − x, starting centred. `None`: the spool follows x_v.
    pub fn with_spool_lag(mut self, tau: Option<f64>) -> Result<Self, ParamError> {
        if let Some(t) = tau {
            ParamError::positive("tau", t)?;
        }
        self.tau = tau;
        Ok(self)
    }

    /// The spool stroke now: the state with a spool lag, else x_v.
    fn stroke(&self, io: &Io<'_>) -> f64 {
        match self.tau {
            Some(_) => io.states()[0],
            None => self.x_v.value(io, 0),
        }
    }

    /// The leak conductance of each main edge, m³/(s·Pa), ≥ 0.
    pub fn with_leakage(mut self, g_leak: f64) -> Result<Self, ParamError> {
        self.g_leak = ParamError::non_negative("g_leak", g_leak)?;
        Ok(self)
    }

    /// The meter-in edge P → W per unit opening, and its partials over (P_P, P_W, P_LS).
    fn meter_in(&self, p_p: f64, p_w: f64, p_ls: f64) -> (f64, [f64; 3]) {
        match self.compensator {
            Compensator::Pre => {
                let dp = p_p - p_w;
                let xi = dp / self.dp_comp;
                let (m, dm) = if xi <= 0.5 {
                    (dp, 1.0)
                } else {
                    let (s, ds) = ramp(xi, self.eps);
                    (self.dp_comp * s, ds)
                };
                if m <= 0.0 {
                    return (0.0, [0.0; 3]);
                }
                let d = self.alpha * reg_root_derivative(m, self.p_tr) * dm;
                (self.alpha * reg_root(m, self.p_tr), [d, -d, 0.0])
            }
            Compensator::Post => {
                let (p_c, dc_ls, dc_w) =
                    smooth_max(p_ls + self.dp_comp, p_w, self.eps * self.dp_comp);
                let dp = p_p - p_c;
                if dp <= 0.0 {
                    return (0.0, [0.0; 3]);
                }
                let d = self.alpha * reg_root_derivative(dp, self.p_tr);
                (
                    self.alpha * reg_root(dp, self.p_tr),
                    [d, -d * dc_w, -d * dc_ls],
                )
            }
        }
    }

    /// The number of ports: P, T, A, B, LS, and X for a post-compensator.
    fn n_ports(&self) -> usize {
        match self.compensator {
            Compensator::Pre => 5,
            Compensator::Post => 6,
        }
    }

    /// Every edge at stroke `x_v` (not yet clamped) and port pressures `p` (P, T, A, B, LS,
    /// X; X unused by a pre-compensator).
    fn edges(&self, x_v: f64, p: &[f64; 6]) -> [EdgeFlow; 7] {
        let x = x_v.clamp(-1.0, 1.0);
        let inside = if (-1.0..=1.0).contains(&x_v) {
            1.0
        } else {
            0.0
        };
        // openings and their slopes: at x = 0 the A side takes the slope (right derivative)
        let (o_a, do_a) = if x >= 0.0 { (x, inside) } else { (0.0, 0.0) };
        let (o_b, do_b) = if x < 0.0 { (-x, -inside) } else { (0.0, 0.0) };
        let sense = |o: f64, d: f64| {
            if o < self.x_ls {
                (o / self.x_ls, d / self.x_ls)
            } else {
                (1.0, 0.0)
            }
        };
        let ((s_a, ds_a), (s_b, ds_b)) = (sense(o_a, do_a), sense(o_b, do_b));
        let g = self.g_leak;
        let rr = |from: usize, to: usize| {
            let dp = p[from] - p[to];
            (reg_root(dp, self.p_tr), reg_root_derivative(dp, self.p_tr))
        };
        // an orifice edge from → to of coefficient k·opening, plus leak g
        let orifice = |from: usize, to: usize, k: f64, o: f64, d_o: f64, leak: f64| {
            let (r, dr) = rr(from, to);
            let mut e = EdgeFlow {
                from,
                to,
                q: k * o * r + leak * (p[from] - p[to]),
                dx: k * d_o * r,
                ..EdgeFlow::default()
            };
            e.dq[from] = k * o * dr + leak;
            e.dq[to] = -e.dq[from];
            e
        };
        let meter_in = |w: usize, o: f64, d_o: f64| {
            let (m, dm) = self.meter_in(p[P], p[w], p[X]);
            let mut e = EdgeFlow {
                from: P,
                to: w,
                q: o * m + g * (p[P] - p[w]),
                dx: d_o * m,
                ..EdgeFlow::default()
            };
            e.dq[P] = o * dm[0] + g;
            e.dq[w] = o * dm[1] - g;
            e.dq[X] = o * dm[2];
            e
        };
        let a = self.alpha;
        [
            meter_in(A, o_a, do_a),
            orifice(B, T, a, o_a, do_a, g),
            meter_in(B, o_b, do_b),
            orifice(A, T, a, o_b, do_b, g),
            orifice(A, LS, self.alpha_ls, s_a, ds_a, 0.0),
            orifice(B, LS, self.alpha_ls, s_b, ds_b, 0.0),
            orifice(LS, T, self.alpha_ls, 1.0 - s_a - s_b, -ds_a - ds_b, 0.0),
        ]
    }

    /// The flows *into* the section at P, T, A, B, LS (and X, always 0) for spool stroke `x_v`
    /// and port pressures `p` (P, T, A, B, LS, X; X unused by a pre-compensator).
    #[must_use]
    pub fn flows(&self, x_v: f64, p: &[f64; 6]) -> [f64; 6] {
        let mut q = [0.0; 6];
        for e in self.edges(x_v, p) {
            q[e.from] += e.q;
            q[e.to] -= e.q;
        }
        q
    }
}

impl LsSection {
    fn pressures(&self, io: &Io<'_>) -> [f64; 6] {
        let mut p = [0.0; 6];
        for (k, pk) in p.iter_mut().enumerate().take(self.n_ports()) {
            *pk = io.e(k, 0);
        }
        p
    }
}

impl Element for LsSection {
    fn kind(&self) -> &str {
        "hydraulics.ls_section"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(
            ["P", "T", "A", "B", "LS", "X"][..self.n_ports()]
                .iter()
                .map(|n| PortSpec::new(n, 1))
                .collect(),
        )
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::FlowOut; self.n_ports()]])
    }
    fn states(&self) -> Vec<StateSpec> {
        match self.tau {
            Some(_) => vec![StateSpec::new("x", 0.0).nominal(1.0)],
            None => Vec::new(),
        }
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.x_v.signal_inputs()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let n = self.n_ports();
        let mut reads: Vec<Slot> = (0..n).map(Slot::Effort).collect();
        if self.tau.is_none() {
            reads.extend((0..self.x_v.n_inputs()).map(Slot::Input));
        }
        vec![Stage {
            writes: (0..n).map(Slot::Flow).collect(),
            reads,
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let p = self.pressures(io);
        let q = self.flows(self.stroke(io), &p);
        for (k, qk) in q.into_iter().enumerate().take(self.n_ports()) {
            io.set_f_in(k, 0, qk);
        }
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let p = self.pressures(io);
        let n = self.n_ports();
        let mut dq = [[0.0; 6]; 6];
        let mut dx = [0.0; 6];
        for e in self.edges(self.stroke(io), &p) {
            for (port, s) in [(e.from, 1.0), (e.to, -1.0)] {
                for (d, de) in dq[port].iter_mut().zip(e.dq) {
                    *d += s * de;
                }
                dx[port] += s * e.dx;
            }
        }
        for port in 0..n {
            let row = jac.row(Slot::Flow(port), 0);
            for (k, d) in dq[port].iter().enumerate().take(n) {
                jac.set(row, jac.effort_col(k, 0), *d);
            }
            match self.tau {
                Some(_) => jac.set(row, jac.state_col(0), dx[port]),
                None => self.x_v.partials(io, 0, |i, d| {
                    jac.set(row, jac.input_col(i, 0), dx[port] * d);
                }),
            }
        }
        true
    }
    fn derivatives(&self, io: &Io<'_>, dx: &mut [f64]) {
        if let Some(tau) = self.tau {
            dx[0] = (self.x_v.value(io, 0).clamp(-1.0, 1.0) - io.states()[0]) / tau;
        }
    }
    fn derivative_partials(&self, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let Some(tau) = self.tau else {
            return true;
        };
        let u = self.x_v.value(io, 0);
        let slope = if (-1.0..=1.0).contains(&u) {
            1.0 / tau
        } else {
            0.0
        };
        let row = jac.derivative_row(0);
        self.x_v.partials(io, 0, |i, d| {
            jac.set(row, jac.input_col(i, 0), slope * d);
        });
        jac.set(row, jac.state_col(0), -1.0 / tau);
        true
    }
}

/// Kind `hydraulics.ls_section`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.ls_section",
    "compensated 4/3 section P, T, A, B, LS (+ X, post): meter-in held by a pre-compensator (spool Δp) or a post-compensator loaded by the LS gallery X (flow sharing); LS senses the open working port, drains to T at centre",
    &[
        ParamDecl::number("q_nom", "m³/s", "nominal flow at full stroke and the nominal spool drop (\"40 L/min\")").positive(),
        ParamDecl::number("dp_nom", "Pa", "nominal spool drop of q_nom").positive().default(1e6),
        ParamDecl::modulated("x_v", "1", "spool stroke, clamped to [−1, 1], e.g. \"spool.out\""),
        ParamDecl::choice("compensator", &["pre", "post"], "pre", "pre: ahead of the spool, holds its drop; post: behind it, loaded by LS (flow sharing)"),
        ParamDecl::number("dp_comp", "Pa", "compensator spring: pre, the spool drop held; post, the spool outlet over the LS pressure")
            .positive()
            .optional("pre: dp_nom; post: 0.1·dp_nom"),
        ParamDecl::number("smoothing", "1", "pre: half-width of the compensator's knee; post: width of the smooth max; fraction of dp_comp")
            .range(Range::closed(0.0, 0.5))
            .default(0.05),
        ParamDecl::number("alpha_ls", "m³/(s·√Pa)", "orifice coefficient of the LS edges (W → LS, LS → T)").positive().default(5e-7),
        ParamDecl::number("ls_stroke", "1", "stroke at which the W → LS edge is fully open and LS → T shut")
            .range(Range { lo_open: true, ..Range::FRACTION })
            .default(0.05),
        ParamDecl::number("g_leak", "m³/(s·Pa)", "leak conductance of each main edge").non_negative().default(1e-13),
        crate::orifice::P_TR,
        ParamDecl::number("tau", "s", "spool time constant: a first-order spool, state x, τ·ẋ = clamp(x_v) − x")
            .positive()
            .optional("the spool follows x_v (feed it from a `lag`)"),
    ],
    build,
)
.example("q_nom = \"40 L/min\", x_v = \"0.5*sin(t)\", compensator = \"post\"");

fn build(p: &dyn Params) -> Result<Box<dyn Element>, BuildError> {
    let word = p.word("compensator")?;
    let compensator = match word.as_str() {
        "pre" => Compensator::Pre,
        "post" => Compensator::Post,
        _ => {
            return Err(BuildError::invalid(
                "compensator",
                format!("unknown compensator \"{word}\""),
            ))
        }
    };
    let dp_nom = p.number("dp_nom")?;
    let dp_comp = p.optional("dp_comp")?.unwrap_or(match compensator {
        Compensator::Pre => dp_nom,
        Compensator::Post => 0.1 * dp_nom,
    });
    let s = LsSection::new(
        compensator,
        p.number("q_nom")?,
        dp_nom,
        p.modulated("x_v")?,
        dp_comp,
        p.number("smoothing")?,
        p.number("p_tr")?,
    )?
    .with_ls_edges(p.number("alpha_ls")?, p.number("ls_stroke")?)?
    .with_leakage(p.number("g_leak")?)?
    .with_spool_lag(p.optional("tau")?)?;
    Ok(Box::new(s))
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact zeros are meant exactly
mod tests;
