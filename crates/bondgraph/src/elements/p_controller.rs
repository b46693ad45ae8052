//! Saturated proportional controller `p_control`: y = clamp(K·(r − u), lo, hi).
//!
//! The paper's eq. 83 is `x_v = clamp(−K_v·(l − l_d), −1, 1)`: gain K_v, set-point r = l_d,
//! measured signal u = l. A stateless signal block (one stage).

use crate::element::{CausalRule, Element, Io, Param, Ports, SignalSpec, Slot};
use crate::error::ParamError;
use crate::kind::{KindDecl, ParamDecl};
use crate::local_jacobian::LocalJacobian;

/// P-controller with gain `gain`, set-point `setpoint` (may be modulated) and output limits.
#[derive(Debug)]
pub struct PController {
    measured: String,
    gain: f64,
    setpoint: Param,
    lo: f64,
    hi: f64,
}

impl PController {
    /// A controller reading `measured`; `lo < hi` (infinite limits allowed), finite gain.
    pub fn new(
        measured: &str,
        gain: f64,
        setpoint: impl Into<Param>,
        lo: f64,
        hi: f64,
    ) -> Result<Self, ParamError> {
        ParamError::finite("gain", gain)?;
        let setpoint = setpoint.into();
        if let Some(r) = setpoint.constant() {
            ParamError::finite("setpoint", r)?;
        }
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return Err(ParamError::Shape {
                param: "limits".into(),
                message: format!("need min < max, got [{lo}, {hi}]"),
            });
        }
        Ok(Self {
            measured: measured.to_owned(),
            gain,
            setpoint,
            lo,
            hi,
        })
    }
}

impl Element for PController {
    fn kind(&self) -> &str {
        "p_control"
    }
    fn ports(&self) -> Ports {
        Ports::Fixed(Vec::new())
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::None
    }
    fn signal_inputs(&self) -> Vec<SignalSpec> {
        let mut v = vec![SignalSpec::scalar(&self.measured)];
        v.extend(self.setpoint.signal_inputs());
        v
    }
    fn signal_outputs(&self) -> Vec<SignalSpec> {
        vec![SignalSpec::scalar("out")]
    }
    fn eval(&self, _: usize, io: &mut Io<'_>) {
        let r = self.setpoint.value(io, 1);
        let y = (self.gain * (r - io.u(0))).clamp(self.lo, self.hi);
        io.set_y(0, 0, y);
    }
    fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let v = self.gain * (self.setpoint.value(io, 1) - io.u(0));
        // Saturated: constant. On a limit itself the value is K·(r − u): its slope.
        if v < self.lo || v > self.hi {
            return true;
        }
        let row = jac.row(Slot::Output(0), 0);
        jac.set(row, jac.input_col(0, 0), -self.gain);
        self.setpoint.partials(io, 1, |i, d| {
            jac.set(row, jac.input_col(1 + i, 0), self.gain * d)
        });
        true
    }
}

/// Kind `p_control`: `out = clamp(−gain·(input − setpoint), min, max)`.
pub const KIND: KindDecl = KindDecl::element(
    "p_control",
    "P-controller: out = clamp(−gain·(input − setpoint), min, max)",
    &[
        ParamDecl::signal("input", "", "measured signal, e.g. \"cyl_piston.l\""),
        ParamDecl::number("gain", "", "proportional gain"),
        ParamDecl::modulated("setpoint", "", "set-point (may read signals and t)"),
        ParamDecl::number("min", "", "lower limit of the output").default(f64::NEG_INFINITY),
        ParamDecl::number("max", "", "upper limit of the output").default(f64::INFINITY),
    ],
    |p| {
        Ok(Box::new(PController::new(
            &p.signal("input")?,
            p.number("gain")?,
            p.modulated("setpoint")?,
            p.number("min")?,
            p.number("max")?,
        )?))
    },
)
.example("input = \"t\", gain = 2.0, setpoint = 1.0, min = -1, max = 1");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;

    #[test]
    fn partials_match_central_differences_inside_and_saturated() {
        let sp = Param::modulated(vec!["r".into()], |_, u| 2.0 * u[0]);
        let c = PController::new("l", 0.3, sp, -1.0, 1.0).unwrap();
        // l, r
        for point in [[3.6, 3.0], [9.0, 0.0], [0.0, 9.0]] {
            assert_eq!(check_partials(&c, &[], &point), Ok(1));
        }
    }

    #[test]
    fn rejects_bad_limits() {
        assert!(PController::new("l", 0.3, 6.0, 1.0, -1.0).is_err());
        assert!(PController::new("l", f64::NAN, 6.0, -1.0, 1.0).is_err());
        assert!(PController::new("l", 0.3, 6.0, -1.0, 1.0).is_ok());
    }
}
