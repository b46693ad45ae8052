//! Expressions as functions of time with exact first and second time derivatives: second-
//! order Taylor arithmetic on jets [x, ẋ, ẍ]. Used for prescribed motions
//! ([`bondgraph::Motion`]: a position source, a moving base), which need ẋ and ẍ of a
//! position given as an expression.
//!
//! Leaves: numbers and parameters (jets [c, 0, 0]), `t` ([t, 1, 0]) and inputs whose
//! derivatives are known (their own [`Motion`]). Rules, for jets a, b:
//! a·b → [ab, a'b + ab', a''b + 2a'b' + ab''];
//! a/b → q = a/b, q' = (a' − q b')/b, q'' = (a'' − 2q'b' − q b'')/b;
//! f(a) → [f(a), f'(a)a', f''(a)a'² + f'(a)a''];
//! atan2(y, x) → θ' = N/D, θ'' = (N'D − N D')/D² with N = xy' − yx', D = x² + y².
//! `abs`, `sign`, `step`, `min`, `max`, `clamp` take the jet of the branch in force (one
//! side's derivatives at a kink). Lookup tables are refused (their second derivative is
//! not continuous): give such data as an input with `interp = "spline"`.

use bondgraph::Motion;

use super::{Expr, Func};

type Jet = [f64; 3];

/// A node of an expression compiled for jets.
enum JNode {
    Num(f64),
    Time,
    Input(Motion),
    Neg(Box<JNode>),
    Bin(char, Box<JNode>, Box<JNode>),
    Call(Func, Vec<JNode>),
}

impl Expr {
    /// This expression as a [`Motion`]: `constant` gives parameters' values, `input` the
    /// motion of an input with known derivatives. A constant expression gives
    /// [`Motion::Const`].
    ///
    /// # Errors
    /// A name that is neither (a signal, an input without derivatives), or a table call:
    /// the message names it.
    pub fn motion(
        &self,
        constant: &dyn Fn(&str) -> Option<f64>,
        input: &dyn Fn(&str) -> Option<Motion>,
    ) -> Result<Motion, String> {
        let node = self.lower_jet(constant, input)?;
        if !varies(&node) {
            return Ok(Motion::Const(eval(&node, 0.0)[0]));
        }
        // the node tree is not Sync (Motion is), so it is shared read-only inside an Arc
        let node = std::sync::Arc::new(node);
        Ok(Motion::law(move |t| eval(&node, t)))
    }

    fn lower_jet(
        &self,
        constant: &dyn Fn(&str) -> Option<f64>,
        input: &dyn Fn(&str) -> Option<Motion>,
    ) -> Result<JNode, String> {
        Ok(match self {
            Self::Num(v) => JNode::Num(*v),
            Self::Name(n) if n == "pi" => JNode::Num(std::f64::consts::PI),
            Self::Name(n) if n == "t" || n == "time" => JNode::Time,
            Self::Name(n) => {
                if let Some(v) = constant(n) {
                    JNode::Num(v)
                } else if let Some(m) = input(n) {
                    JNode::Input(m)
                } else {
                    return Err(format!(
                        "`{n}` has no known time derivatives: a motion may read `t`, parameters and inputs from `sea` or from data with interp = \"spline\""
                    ));
                }
            }
            Self::Neg(a) => JNode::Neg(Box::new(a.lower_jet(constant, input)?)),
            Self::Bin(op, a, b) => JNode::Bin(
                *op,
                Box::new(a.lower_jet(constant, input)?),
                Box::new(b.lower_jet(constant, input)?),
            ),
            Self::Call(f, args) => {
                let func = Func::of(f).ok_or_else(|| {
                    format!("`{f}` cannot be differentiated in time here (a table or an unknown function): give such data as an input with interp = \"spline\"")
                })?;
                JNode::Call(
                    func,
                    args.iter()
                        .map(|a| a.lower_jet(constant, input))
                        .collect::<Result<_, _>>()?,
                )
            }
        })
    }
}

fn varies(n: &JNode) -> bool {
    match n {
        JNode::Num(_) => false,
        JNode::Time => true,
        JNode::Input(m) => !m.is_still(),
        JNode::Neg(a) => varies(a),
        JNode::Bin(_, a, b) => varies(a) || varies(b),
        JNode::Call(_, args) => args.iter().any(varies),
    }
}

/// f(a) by the chain rule with f, f', f'' at a's value.
fn chain(a: Jet, f: f64, d1: f64, d2: f64) -> Jet {
    [f, d1 * a[1], d2 * a[1] * a[1] + d1 * a[2]]
}

fn mul(a: Jet, b: Jet) -> Jet {
    [
        a[0] * b[0],
        a[1] * b[0] + a[0] * b[1],
        a[2] * b[0] + 2.0 * a[1] * b[1] + a[0] * b[2],
    ]
}

fn div(a: Jet, b: Jet) -> Jet {
    let q = a[0] / b[0];
    let q1 = (a[1] - q * b[1]) / b[0];
    let q2 = (a[2] - 2.0 * q1 * b[1] - q * b[2]) / b[0];
    [q, q1, q2]
}

fn ln(a: Jet) -> Jet {
    chain(a, a[0].ln(), 1.0 / a[0], -1.0 / (a[0] * a[0]))
}

fn exp(a: Jet) -> Jet {
    let e = a[0].exp();
    chain(a, e, e, e)
}

/// a^b: a constant exponent by the power rule (negative bases fine), else exp(b·ln a).
fn pow(a: Jet, b: Jet) -> Jet {
    if b[1] == 0.0 && b[2] == 0.0 {
        let c = b[0];
        let v = a[0].powf(c);
        let d1 = if c == 0.0 { 0.0 } else { c * a[0].powf(c - 1.0) };
        let d2 = if c == 0.0 || c == 1.0 {
            0.0
        } else {
            c * (c - 1.0) * a[0].powf(c - 2.0)
        };
        return chain(a, v, d1, d2);
    }
    exp(mul(b, ln(a)))
}

fn eval(n: &JNode, t: f64) -> Jet {
    match n {
        JNode::Num(v) => [*v, 0.0, 0.0],
        JNode::Time => [t, 1.0, 0.0],
        JNode::Input(m) => m.eval(t),
        JNode::Neg(a) => {
            let a = eval(a, t);
            [-a[0], -a[1], -a[2]]
        }
        JNode::Bin(op, a, b) => {
            let (a, b) = (eval(a, t), eval(b, t));
            match op {
                '+' => [a[0] + b[0], a[1] + b[1], a[2] + b[2]],
                '-' => [a[0] - b[0], a[1] - b[1], a[2] - b[2]],
                '*' => mul(a, b),
                '/' => div(a, b),
                _ => pow(a, b),
            }
        }
        JNode::Call(f, args) => {
            let mut v = [[0.0; 3]; 3];
            for (k, a) in args.iter().take(3).enumerate() {
                v[k] = eval(a, t);
            }
            call(*f, &v, args, t)
        }
    }
}

fn call(f: Func, v: &[Jet; 3], args: &[JNode], t: f64) -> Jet {
    let a = v[0];
    let x = a[0];
    match f {
        Func::Sqrt => {
            let s = x.sqrt();
            chain(a, s, 0.5 / s, -0.25 / (s * x))
        }
        Func::Exp => exp(a),
        Func::Ln => ln(a),
        Func::Log10 => {
            let l = ln(a);
            let k = std::f64::consts::LN_10;
            [l[0] / k, l[1] / k, l[2] / k]
        }
        Func::Sin => chain(a, x.sin(), x.cos(), -x.sin()),
        Func::Cos => chain(a, x.cos(), -x.sin(), -x.cos()),
        Func::Tan => {
            let tn = x.tan();
            let s = 1.0 + tn * tn;
            chain(a, tn, s, 2.0 * tn * s)
        }
        Func::Asin => {
            let r = 1.0 - x * x;
            chain(a, x.asin(), 1.0 / r.sqrt(), x / (r * r.sqrt()))
        }
        Func::Acos => {
            let r = 1.0 - x * x;
            chain(a, x.acos(), -1.0 / r.sqrt(), -x / (r * r.sqrt()))
        }
        Func::Atan => {
            let r = 1.0 + x * x;
            chain(a, x.atan(), 1.0 / r, -2.0 * x / (r * r))
        }
        Func::Sinh => chain(a, x.sinh(), x.cosh(), x.sinh()),
        Func::Cosh => chain(a, x.cosh(), x.sinh(), x.cosh()),
        Func::Tanh => {
            let th = x.tanh();
            let s = 1.0 - th * th;
            chain(a, th, s, -2.0 * th * s)
        }
        Func::Abs => {
            if x >= 0.0 {
                a
            } else {
                [-a[0], -a[1], -a[2]]
            }
        }
        Func::Sign => [
            if x > 0.0 {
                1.0
            } else if x < 0.0 {
                -1.0
            } else {
                0.0
            },
            0.0,
            0.0,
        ],
        Func::Step => [if x >= 0.0 { 1.0 } else { 0.0 }, 0.0, 0.0],
        Func::Deg | Func::Rad => {
            let k = if f == Func::Deg {
                180.0 / std::f64::consts::PI
            } else {
                std::f64::consts::PI / 180.0
            };
            [k * a[0], k * a[1], k * a[2]]
        }
        Func::Pow => pow(a, v[1]),
        Func::Atan2 => {
            let (y, xx) = (v[0], v[1]);
            let d = xx[0] * xx[0] + y[0] * y[0];
            let nn = xx[0] * y[1] - y[0] * xx[1];
            let n1 = xx[0] * y[2] - y[0] * xx[2];
            let d1 = 2.0 * (xx[0] * xx[1] + y[0] * y[1]);
            [y[0].atan2(xx[0]), nn / d, (n1 * d - nn * d1) / (d * d)]
        }
        Func::Min | Func::Max => {
            // more than three arguments: evaluate the rest here
            let mut best = a;
            for (k, arg) in args.iter().enumerate().skip(1) {
                let w = if k < 3 { v[k] } else { eval(arg, t) };
                let better = if f == Func::Min {
                    w[0] < best[0]
                } else {
                    w[0] > best[0]
                };
                if better || w[0].is_nan() {
                    best = w;
                }
            }
            best
        }
        Func::Clamp => {
            if v[1][0] > v[2][0] {
                [f64::NAN; 3]
            } else if x < v[1][0] {
                v[1]
            } else if x > v[2][0] {
                v[2]
            } else {
                a
            }
        }
        Func::Table(_) => [f64::NAN; 3],
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;

    fn motion(src: &str) -> Motion {
        let consts = |n: &str| (n == "A").then_some(0.5);
        let inputs = |n: &str| (n == "w").then(|| Motion::law(|t| [t.sin(), t.cos(), -t.sin()]));
        Expr::parse(src).unwrap().motion(&consts, &inputs).unwrap()
    }

    /// Every rule against central differences of the value and of the first derivative.
    #[test]
    fn jets_match_central_differences() {
        for src in [
            "A*sin(2*t) + t^3/6",
            "sqrt(1 + t^2) * exp(-0.1*t)",
            "ln(2 + w) / (3 + cos(t))",
            "atan2(w, 2 + t) + tanh(w) + atan(t) - asin(0.5*w) + acos(0.3*w)",
            "pow(2 + w, 1.5) + (1 + t)^(0.5*t) + log10(5 + t) + cosh(w) - sinh(0.2*t) + tan(0.3*w)",
            "deg(w) + rad(t) + abs(w - 0.2) + max(w, 0.1*t, -1) + min(w, 2) + clamp(w, -0.5, 0.5)",
        ] {
            let m = motion(src);
            for t in [0.3, 1.1, 2.9] {
                let [x, v, a] = m.eval(t);
                let h = 1e-5;
                let (p, q) = (m.eval(t + h), m.eval(t - h));
                assert!((v - (p[0] - q[0]) / (2.0 * h)).abs() < 1e-6 * (1.0 + v.abs()), "{src}: ẋ at {t}");
                assert!((a - (p[1] - q[1]) / (2.0 * h)).abs() < 1e-6 * (1.0 + a.abs()), "{src}: ẍ at {t}");
                let plain = Expr::parse(src).unwrap().eval(&|n| match n {
                    "A" => Some(0.5),
                    "w" => Some(t.sin()),
                    "t" => Some(t),
                    _ => None,
                });
                assert!((x - plain.unwrap()).abs() < 1e-12, "{src}: value at {t}");
            }
        }
    }

    #[test]
    fn constants_stand_still_and_unknown_names_or_tables_are_refused() {
        assert_eq!(motion("2*A + pi").constant(), Some(1.0 + std::f64::consts::PI));
        let none = |_: &str| None::<f64>;
        let no_input = |_: &str| None::<Motion>;
        let e = Expr::parse("spring.q + t").unwrap().motion(&none, &no_input).unwrap_err();
        assert!(e.contains("spring.q"), "{e}");
        let e = Expr::parse_with("lut(t)", &[("lut".to_owned(), 1)]).unwrap().motion(&none, &no_input).unwrap_err();
        assert!(e.contains("lut"), "{e}");
    }
}
