//! Arithmetic expressions in model files: `"pi/4*d^2"`, `"1/k"`, `"0.5 + 0.1*spring.q"`.
//!
//! Numbers, named parameters, signals (dotted names such as `spring.q`, and `t`), the
//! operators `+ - * / ^` (`^` binds tightest and to the right; `-2^2` is −4), parentheses and
//! the functions listed in [`FUNCTIONS`]. Always floating point: `1/2` is 0.5.

use std::fmt;

mod parser;
use parser::Parser;

/// Functions an expression may call, with their number of arguments (`None`: one or more).
pub const FUNCTIONS: &[(&str, Option<usize>)] = &[
    ("sqrt", Some(1)),
    ("exp", Some(1)),
    ("ln", Some(1)),
    ("log10", Some(1)),
    ("sin", Some(1)),
    ("cos", Some(1)),
    ("tan", Some(1)),
    ("asin", Some(1)),
    ("acos", Some(1)),
    ("atan", Some(1)),
    ("atan2", Some(2)),
    ("sinh", Some(1)),
    ("cosh", Some(1)),
    ("tanh", Some(1)),
    ("abs", Some(1)),
    ("sign", Some(1)),
    ("step", Some(1)),
    ("pow", Some(2)),
    ("min", None),
    ("max", None),
    ("clamp", Some(3)),
    ("deg", Some(1)),
    ("rad", Some(1)),
];

/// Longest expression, in characters.
pub const MAX_EXPR_LEN: usize = 10_000;

/// Deepest expression: every parenthesis, sign, function call and operator is one level, and
/// a chain `a + b + c` is as deep as it has operators. Deeper expressions would overflow the
/// stack of the parser and of the evaluation.
pub const MAX_EXPR_DEPTH: usize = 200;

/// Names that are not parameters: `pi` and `t` (time).
pub const RESERVED: &[&str] = &["pi", "t", "time"];

/// A parse error at a character position of the expression.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExprError {
    /// 0-based character position.
    pub pos: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} (at character {})", self.message, self.pos + 1)
    }
}

/// A parsed expression; identifiers are still names.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A number.
    Num(f64),
    /// A name: a parameter, a signal, `t` or `pi`.
    Name(String),
    /// Unary minus.
    Neg(Box<Expr>),
    /// Binary operation.
    Bin(char, Box<Expr>, Box<Expr>),
    /// Function call.
    Call(String, Vec<Expr>),
}

impl Expr {
    /// Parse `src`.
    pub fn parse(src: &str) -> Result<Self, ExprError> {
        let n = src.chars().count();
        if n > MAX_EXPR_LEN {
            return Err(ExprError {
                pos: MAX_EXPR_LEN,
                message: format!(
                    "the expression has {n} characters, more than {MAX_EXPR_LEN}; split it into named parameters"
                ),
            });
        }
        let chars: Vec<char> = src.chars().collect();
        Parser::whole(&chars)
    }

    /// Every name used, in order of first appearance.
    #[must_use]
    pub fn names(&self) -> Vec<String> {
        let mut out = Vec::new();
        self.collect(&mut out);
        out
    }

    fn collect(&self, out: &mut Vec<String>) {
        match self {
            Self::Num(_) => {}
            Self::Name(n) => {
                if !out.contains(n) {
                    out.push(n.clone());
                }
            }
            Self::Neg(a) => a.collect(out),
            Self::Bin(_, a, b) => {
                a.collect(out);
                b.collect(out);
            }
            Self::Call(_, args) => args.iter().for_each(|a| a.collect(out)),
        }
    }

    /// Evaluate, looking names up with `lookup` (`pi` is built in).
    pub fn eval(&self, lookup: &dyn Fn(&str) -> Option<f64>) -> Result<f64, String> {
        Ok(match self {
            Self::Num(v) => *v,
            Self::Name(n) if n == "pi" => std::f64::consts::PI,
            Self::Name(n) => lookup(n).ok_or_else(|| format!("unknown name `{n}`"))?,
            Self::Neg(a) => -a.eval(lookup)?,
            Self::Bin(op, a, b) => {
                let (a, b) = (a.eval(lookup)?, b.eval(lookup)?);
                binary(*op, a, b)
            }
            Self::Call(f, args) => {
                let v: Result<Vec<f64>, String> = args.iter().map(|a| a.eval(lookup)).collect();
                call(f, &v?)
            }
        })
    }

    /// Compile for fast repeated evaluation: every name becomes a constant (via `constant`) or
    /// an input slot (in the order of `inputs`).
    pub fn compile(
        &self,
        constant: &dyn Fn(&str) -> Option<f64>,
        inputs: &[String],
    ) -> Result<Compiled, String> {
        Ok(Compiled(self.lower(constant, inputs)?))
    }

    fn lower(
        &self,
        constant: &dyn Fn(&str) -> Option<f64>,
        inputs: &[String],
    ) -> Result<Node, String> {
        Ok(match self {
            Self::Num(v) => Node::Num(*v),
            Self::Name(n) if n == "pi" => Node::Num(std::f64::consts::PI),
            Self::Name(n) => {
                if let Some(v) = constant(n) {
                    Node::Num(v)
                } else if let Some(i) = inputs.iter().position(|x| x == n) {
                    Node::Input(i)
                } else {
                    return Err(format!("unknown name `{n}`"));
                }
            }
            Self::Neg(a) => Node::Neg(Box::new(a.lower(constant, inputs)?)),
            Self::Bin(op, a, b) => Node::Bin(
                *op,
                Box::new(a.lower(constant, inputs)?),
                Box::new(b.lower(constant, inputs)?),
            ),
            Self::Call(f, args) => Node::Call(
                f.clone(),
                args.iter()
                    .map(|a| a.lower(constant, inputs))
                    .collect::<Result<_, _>>()?,
            ),
        })
    }
}

fn binary(op: char, a: f64, b: f64) -> f64 {
    match op {
        '+' => a + b,
        '-' => a - b,
        '*' => a * b,
        '/' => a / b,
        _ => a.powf(b),
    }
}

fn call(f: &str, v: &[f64]) -> f64 {
    match f {
        "sqrt" => v[0].sqrt(),
        "exp" => v[0].exp(),
        "ln" => v[0].ln(),
        "log10" => v[0].log10(),
        "sin" => v[0].sin(),
        "cos" => v[0].cos(),
        "tan" => v[0].tan(),
        "asin" => v[0].asin(),
        "acos" => v[0].acos(),
        "atan" => v[0].atan(),
        "atan2" => v[0].atan2(v[1]),
        "sinh" => v[0].sinh(),
        "cosh" => v[0].cosh(),
        "tanh" => v[0].tanh(),
        "abs" => v[0].abs(),
        "sign" => {
            if v[0] > 0.0 {
                1.0
            } else if v[0] < 0.0 {
                -1.0
            } else {
                0.0
            }
        }
        "step" => {
            if v[0] >= 0.0 {
                1.0
            } else {
                0.0
            }
        }
        "pow" => v[0].powf(v[1]),
        "min" => v.iter().copied().fold(f64::INFINITY, f64::min),
        "max" => v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        // bounds in the wrong order give NaN, which the run reports, not a silent `hi`
        "clamp" if v[1] > v[2] => f64::NAN,
        "clamp" => v[0].max(v[1]).min(v[2]),
        "deg" => v[0].to_degrees(),
        "rad" => v[0].to_radians(),
        _ => f64::NAN,
    }
}

#[derive(Clone, Debug)]
enum Node {
    Num(f64),
    Input(usize),
    Neg(Box<Node>),
    Bin(char, Box<Node>, Box<Node>),
    Call(String, Vec<Node>),
}

/// A compiled expression: constants folded in, signals read from an input slice.
#[derive(Clone, Debug)]
pub struct Compiled(Node);

impl Compiled {
    /// Evaluate with the inputs in the order given to [`Expr::compile`].
    #[must_use]
    pub fn eval(&self, inputs: &[f64]) -> f64 {
        eval_node(&self.0, inputs)
    }
    /// The value if the expression reads no inputs (it may still be NaN or infinite).
    #[must_use]
    pub fn constant(&self) -> Option<f64> {
        (!reads_inputs(&self.0)).then(|| eval_node(&self.0, &[]))
    }
}

fn reads_inputs(n: &Node) -> bool {
    match n {
        Node::Num(_) => false,
        Node::Input(_) => true,
        Node::Neg(a) => reads_inputs(a),
        Node::Bin(_, a, b) => reads_inputs(a) || reads_inputs(b),
        Node::Call(_, args) => args.iter().any(reads_inputs),
    }
}

fn eval_node(n: &Node, u: &[f64]) -> f64 {
    match n {
        Node::Num(v) => *v,
        Node::Input(i) => u[*i],
        Node::Neg(a) => -eval_node(a, u),
        Node::Bin(op, a, b) => binary(*op, eval_node(a, u), eval_node(b, u)),
        Node::Call(f, args) => {
            let mut buf = [0.0; 8];
            let n = args.len().min(8);
            for (k, a) in args.iter().take(n).enumerate() {
                buf[k] = eval_node(a, u);
            }
            call(f, &buf[..n])
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn ev(s: &str) -> f64 {
        Expr::parse(s)
            .unwrap()
            .eval(&|n| (n == "k").then_some(4.0))
            .unwrap()
    }

    #[test]
    fn arithmetic_is_floating_point_with_usual_precedence() {
        assert!((ev("1/2") - 0.5).abs() < 1e-15);
        assert!((ev("-2^2") + 4.0).abs() < 1e-15);
        assert!((ev("2^3^2") - 512.0).abs() < 1e-9);
        assert!((ev("1 + 2*3 - 4/2") - 5.0).abs() < 1e-15);
        assert!((ev("pi/4*0.24^2") - 0.045_238_934_211_693_02).abs() < 1e-15);
        assert!((ev("sqrt(k)*max(1, 2, 3)") - 6.0).abs() < 1e-15);
        assert!((ev("1.5e3 + 2E-1") - 1500.2).abs() < 1e-12);
        assert!((ev("clamp(5, -1, 1)") - 1.0).abs() < 1e-15);
    }

    #[test]
    fn names_include_dotted_signals() {
        let e = Expr::parse("0.5 + 0.1*spring.q - lever.2.e + arm.q[1]").unwrap();
        assert_eq!(e.names(), ["spring.q", "lever.2.e", "arm.q[1]"]);
    }

    #[test]
    fn errors_point_at_the_problem() {
        assert_eq!(Expr::parse("1 + ").unwrap_err().pos, 4);
        assert!(Expr::parse("foo(1)")
            .unwrap_err()
            .message
            .contains("unknown function"));
        assert!(Expr::parse("(1 + 2")
            .unwrap_err()
            .message
            .contains("missing `)`"));
        assert!(Expr::parse("atan2(1)")
            .unwrap_err()
            .message
            .contains("takes 2"));
        assert!(Expr::parse("2 $ 3").is_err());
    }

    /// Issue "hardening" #1: ~8 300 nested parentheses, 15 800 minus signs or a 52 000-term
    /// sum overflowed the stack (abort, exit 134). Each is now refused, on a small stack too.
    #[test]
    fn deep_or_long_expressions_are_refused_not_a_stack_overflow() {
        let deep = [
            format!("{}10{}", "(".repeat(9000), ")".repeat(9000)),
            format!("{}10", "-".repeat(15_800)),
            format!("{}10", "+".repeat(15_800)),
            vec!["1"; 4_000].join("+"),
            vec!["1"; 4_000].join("*"),
            format!("{}1{}", "sqrt(".repeat(300), ")".repeat(300)),
            format!("{}2", "2^".repeat(300)),
            vec!["1"; 52_000].join("+"),
        ];
        let handle = std::thread::Builder::new()
            .stack_size(256 * 1024)
            .spawn(move || {
                deep.iter()
                    .map(|s| Expr::parse(s).unwrap_err().message)
                    .collect::<Vec<_>>()
            })
            .unwrap();
        for m in handle.join().unwrap() {
            assert!(
                m.contains("nested more than 200") || m.contains("more than 10000"),
                "{m}"
            );
        }
        // up to the limits: parsed and evaluated, also on a small stack
        let fine = std::thread::Builder::new()
            .stack_size(256 * 1024)
            .spawn(|| {
                let sum = vec!["1"; 199].join("+");
                let parens = format!("{}2{}", "(".repeat(199), ")".repeat(199));
                let signs = format!("{}2", "-".repeat(198));
                [sum, parens, signs].map(|s| Expr::parse(&s).unwrap().eval(&|_| None).unwrap())
            })
            .unwrap()
            .join()
            .unwrap();
        assert!(fine
            .iter()
            .zip([199.0, 2.0, 2.0])
            .all(|(a, b)| (a - b).abs() < 1e-12));
    }

    /// Issue "hardening" #10: `clamp(0, 1, x)` (bounds first) was accepted and gave 1.
    #[test]
    fn clamp_with_its_arguments_in_the_wrong_order_is_refused() {
        for bad in ["clamp(0, 1, x)", "clamp(x, 1, 0)", "clamp(x, 2*pi, 0)"] {
            let e = Expr::parse(bad).unwrap_err();
            assert!(e.message.contains("clamp(x, lo, hi)"), "{bad}: {e}");
        }
        assert!((ev("clamp(k, 0, 1)") - 1.0).abs() < 1e-15);
        // bounds only known at run time, in the wrong order: NaN, not a silent `hi`
        let e = Expr::parse("clamp(x, lo, hi)").unwrap();
        let v = e
            .eval(&|n| match n {
                "x" => Some(0.5),
                "lo" => Some(1.0),
                "hi" => Some(0.0),
                _ => None,
            })
            .unwrap();
        assert!(v.is_nan());
    }

    #[test]
    fn compiled_matches_interpreted() {
        let e = Expr::parse("k*x + sin(t)").unwrap();
        let c = e
            .compile(&|n| (n == "k").then_some(4.0), &["x".into(), "t".into()])
            .unwrap();
        let want = e.eval(&|n| match n {
            "k" => Some(4.0),
            "x" => Some(0.5),
            "t" => Some(1.0),
            _ => None,
        });
        assert!((c.eval(&[0.5, 1.0]) - want.unwrap()).abs() < 1e-15);
    }
}
