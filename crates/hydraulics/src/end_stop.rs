//! End stop `hydraulics.end_stop`: a stiff spring–damper that acts only past either end of
//! the stroke, so that a drive commanded beyond its stroke stays physical.
//!
//! With stroke s (a signal, usually `<piston>.s`), limits `s_min < s_max`, stiffness k,
//! damping c and contact width δ, the force it takes from the rod (power in positive, f_in =
//! ṡ the extension rate) is
//!
//! ```text
//! s > s_max:  e = max(0,  k·(s − s_max) + c·min(1, (s − s_max)/δ)·ṡ)
//! s < s_min:  e = min(0, −k·(s_min − s) + c·min(1, (s_min − s)/δ)·ṡ)
//! otherwise:  e = 0
//! ```
//!
//! The damping grows over the first δ of penetration, so the force is continuous in s at
//! contact; the clamps keep the stop from pulling (it only pushes). It dissipates e·ṡ ≥ 0 on
//! penetration and returns the spring energy on release. Causality: resistance (the rod sets
//! the flow, the stop the force). Bond it *from* the rod's 1-junction so that its flow in is
//! the extension rate: on that junction the rod then delivers F_c − e.

use bondgraph::kind::{KindDecl, ParamDecl};
use bondgraph::{
    CausalRule, Element, Io, LocalJacobian, Param, ParamError, PortCausality, PortSpec, Ports,
    SignalSpec, Slot, Stage,
};

/// End stop on the stroke range `[s_min, s_max]` (m), stiffness `k` (N/m, > 0), damping `c`
/// (N·s/m, ≥ 0), contact width `width` (m, > 0), reading the stroke `stroke` (m).
#[derive(Debug)]
pub struct EndStop {
    stroke: Param,
    s_min: f64,
    s_max: f64,
    k: f64,
    c: f64,
    width: f64,
}

impl EndStop {
    /// An end stop; see the struct documentation for the parameters.
    pub fn new(
        stroke: impl Into<Param>,
        s_min: f64,
        s_max: f64,
        k: f64,
        c: f64,
        width: f64,
    ) -> Result<Self, ParamError> {
        ParamError::finite("s_min", s_min)?;
        ParamError::finite("s_max", s_max)?;
        if s_min >= s_max {
            return Err(ParamError::Shape {
                param: "s_max".into(),
                message: format!("need s_min < s_max, got [{s_min}, {s_max}]"),
            });
        }
        ParamError::positive("k", k)?;
        ParamError::non_negative("c", c)?;
        ParamError::positive("width", width)?;
        Ok(Self {
            stroke: stroke.into(),
            s_min,
            s_max,
            k,
            c,
            width,
        })
    }

    /// Force taken from the rod at stroke `s` and extension rate `v` (N).
    #[must_use]
    pub fn force(&self, s: f64, v: f64) -> f64 {
        if s > self.s_max {
            let d = s - self.s_max;
            (self.k * d + self.c * (d / self.width).min(1.0) * v).max(0.0)
        } else if s < self.s_min {
            let d = self.s_min - s;
            (-self.k * d + self.c * (d / self.width).min(1.0) * v).min(0.0)
        } else {
            0.0
        }
    }

    /// The partials of [`force`](Self::force) with respect to s and v: `(∂e/∂s, ∂e/∂v)`.
    /// Where the clamp holds the force at 0 both are 0.
    #[must_use]
    pub fn force_partials(&self, s: f64, v: f64) -> (f64, f64) {
        let (d, sign) = if s > self.s_max {
            (s - self.s_max, 1.0)
        } else if s < self.s_min {
            (self.s_min - s, -1.0)
        } else {
            return (0.0, 0.0);
        };
        // e = clamp(sign·k·d + c·min(1, d/δ)·v) with dd/ds = sign
        let w = (d / self.width).min(1.0);
        let inner = sign * self.k * d + self.c * w * v;
        if inner * sign <= 0.0 {
            return (0.0, 0.0);
        }
        let dw_dd = if d < self.width {
            1.0 / self.width
        } else {
            0.0
        };
        (self.k + sign * self.c * dw_dd * v, self.c * w)
    }
}

impl Element for EndStop {
    fn kind(&self) -> &str {
        "hydraulics.end_stop"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(vec![PortSpec::new("1", 1)])
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::Resistive(vec![vec![PortCausality::EffortOut]])
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        self.stroke.signal_inputs()
    }
    fn stages(&self, _: &[PortCausality]) -> Vec<Stage> {
        let mut reads = vec![Slot::Flow(0)];
        reads.extend((0..self.stroke.n_inputs()).map(Slot::Input));
        vec![Stage {
            writes: vec![Slot::Effort(0)],
            reads,
        }]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let f = self.force(self.stroke.value(io, 0), io.f_in(0, 0));
        io.set_e(0, 0, f);
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let (de_ds, de_dv) = self.force_partials(self.stroke.value(io, 0), io.f_in(0, 0));
        let row = jac.row(Slot::Effort(0), 0);
        jac.set(row, jac.flow_col(0, 0), de_dv);
        self.stroke
            .partials(io, 0, |i, d| jac.set(row, jac.input_col(i, 0), de_ds * d));
        true
    }
}

/// Kind `hydraulics.end_stop`.
pub const KIND: KindDecl = KindDecl::element(
    "hydraulics.end_stop",
    "stiff spring–damper past either end of the stroke",
    &[
        ParamDecl::modulated("stroke", "m", "stroke signal, e.g. \"cyl.s\""),
        ParamDecl::number("s_min", "m", "lower end of the stroke").default(0.0),
        ParamDecl::number("s_max", "m", "upper end of the stroke"),
        ParamDecl::number("k", "N/m", "stiffness").positive(),
        ParamDecl::number(
            "c",
            "N·s/m",
            "damping; near 2√(k·m) for a well-damped landing",
        )
        .non_negative(),
        ParamDecl::number(
            "width",
            "m",
            "contact width δ, small against the resting penetration F/k",
        )
        .positive()
        .default(1e-5),
    ],
    |p| {
        Ok(Box::new(EndStop::new(
            p.modulated("stroke")?,
            p.number("s_min")?,
            p.number("s_max")?,
            p.number("k")?,
            p.number("c")?,
            p.number("width")?,
        )?))
    },
)
.example("stroke = \"t\", s_max = 0.5, k = 1e8, c = 1e5");

#[cfg(test)]
#[allow(clippy::float_cmp)] // exact zeros and copied parameters are meant exactly
mod tests {
    use super::*;

    #[test]
    fn acts_only_past_the_ends_and_only_pushes() {
        let e = EndStop::new(0.0, 0.0, 2.7, 1e9, 1e6, 1e-3).unwrap();
        assert_eq!(e.force(1.0, 5.0), 0.0);
        assert_eq!(e.force(2.7, 5.0), 0.0);
        // 1 mm past the top, extending at 0.1 m/s: full damping
        assert!((e.force(2.701, 0.1) - (1e6 + 1e5)).abs() < 1e-3);
        // half the contact width, retracting fast: the damper may not pull
        assert_eq!(e.force(2.7005, -10.0), 0.0);
        // below the bottom, retracting: pushes outward (negative force taken from the rod)
        assert!((e.force(-2e-3, -0.1) - (-2e6 - 1e5)).abs() < 1e-3);
        assert_eq!(e.force(-1e-4, 50.0), 0.0);
        // continuous at contact
        assert!(e.force(2.7 + 1e-12, 1.0).abs() < 1e-2);
    }

    #[test]
    fn partials_match_central_differences_in_every_regime() {
        use bondgraph::check_partials;
        let stroke = Param::modulated(vec!["s".into()], |_, u| u[0]);
        let e = EndStop::new(stroke, 0.0, 2.7, 1e9, 1e6, 1e-3).unwrap();
        let port = [(1, -1.0, PortCausality::EffortOut)];
        // (s, v): inside; past the top in and beyond the contact width; past the bottom;
        // pulling (clamped)
        for (s, v) in [
            (1.0, 0.3),
            (2.7004, 0.1),
            (2.705, -0.2),
            (-4e-4, -0.1),
            (-3e-3, 0.5),
            (2.7005, -10.0),
        ] {
            // F, v_in, s
            assert_eq!(check_partials(&e, &port, &[0.0, v, s]), Ok(1), "{s} {v}");
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(EndStop::new(0.0, 1.0, 1.0, 1e9, 1e6, 1e-3).is_err());
        assert!(EndStop::new(0.0, 0.0, 1.0, 0.0, 1e6, 1e-3).is_err());
        assert!(EndStop::new(0.0, 0.0, 1.0, 1e9, -1.0, 1e-3).is_err());
        assert!(EndStop::new(0.0, 0.0, 1.0, 1e9, 1e6, 0.0).is_err());
    }
}
