//! LS line `hydraulics.ls_line`: the load-sense signal line from the valve's LS gallery (or
//! its last shuttle) to the pump's LS port, a volume with a bleed to tank, as one component.
//!
//! ```text
//!  p (0) ─⇀ volume (C: V, β; P_LS)        members, named <instance>_<local>:
//!  p ─⇀ bleed.a, bleed.b ─⇀ tank (Se p_t)    j, volume, bleed, tank
//!  bleed: Q = α_b·regRoot(P_LS − p_t),  α_b = q_bleed/regRoot(dp_bleed)   (an orifice)
//! ```
//!
//! The bleed (a fixed orifice; a datasheet gives it as a flow at a pressure) drains the line when every section
//! is centred, so the pump falls back to its standby pressure instead of staying at the last
//! load pressure trapped in the line; it draws a small flow through the open shuttle and the
//! working section's LS edge, whose drop is the "bleed drop" below the load pressure. The
//! volume gives the line its pressure state (V/β·dP/dt = Σ Q_in − Q_bleed). Exposed port `p`
//! (bond the shuttle's outlet and the pump's `LS` port to it).

use bondgraph::kind::{BuildError, KindDecl, ParamDecl, Params};
use bondgraph::{Composite, ZeroJunction};

use bondgraph::EffortSource;

use crate::orifice::{self, reg_root};
use crate::{Chamber, Orifice};

/// Kind `hydraulics.ls_line`.
pub const KIND: KindDecl = KindDecl::composite(
    "hydraulics.ls_line",
    "LS signal line: a volume with an orifice bleed to tank, q_bleed at dp_bleed; port p",
    &[
        ParamDecl::number("volume", "m³", "volume of the signal line").positive(),
        ParamDecl::number("beta", "Pa", "bulk modulus")
            .positive()
            .default(1.5e9),
        ParamDecl::number("q_bleed", "m³/s", "bleed flow at dp_bleed (\"0.2 L/min\")")
            .positive()
            .default(3.333_333e-6),
        ParamDecl::number(
            "dp_bleed",
            "Pa",
            "pressure at which the bleed passes q_bleed",
        )
        .positive()
        .default(2e6),
        ParamDecl::number("p_t", "Pa", "tank pressure").default(0.0),
        ParamDecl::number("p0", "Pa", "initial pressure").default(0.0),
        orifice::P_TR,
    ],
    build,
)
.example("volume = 2e-5");

fn build(p: &dyn Params) -> Result<Composite, BuildError> {
    let p_tr = p.number("p_tr")?;
    let alpha = p.number("q_bleed")? / reg_root(p.number("dp_bleed")?, p_tr);
    let mut c = Composite::default();
    c.element("j", ZeroJunction)
        .element(
            "volume",
            Chamber::fixed(p.number("volume")?, p.number("beta")?, p.number("p0")?)?,
        )
        .element("bleed", Orifice::new(alpha, 1.0, p_tr)?)
        .element("tank", EffortSource::new(p.number("p_t")?));
    c.bond("b_v", "j", "volume")
        .bond("b_bleed", "j", "bleed.a")
        .bond("b_tank", "bleed.b", "tank");
    c.port("p", "j");
    Ok(c)
}
