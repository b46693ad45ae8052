//! Arithmetic expressions in model files: `"pi/4*d^2"`, `"1/k"`, `"0.5 + 0.1*spring.q"`.
//!
//! Numbers, named parameters, signals (dotted names such as `spring.q`, and `t`), the
//! operators `+ - * / ^` (`^` binds tightest and to the right; `-2^2` is −4), parentheses and
//! the functions listed in [`FUNCTIONS`]. Always floating point: `1/2` is 0.5.

use std::fmt;
use std::sync::Arc;

use crate::tables::Tables;

mod jet;
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
        Parser::whole(&chars, &[])
    }

    /// Parse `src`, where the lookup tables `tables` (name, number of arguments) may be
    /// called like functions: `eta(n, dp)`.
    pub fn parse_with(src: &str, tables: &[(String, usize)]) -> Result<Self, ExprError> {
        let n = src.chars().count();
        if n > MAX_EXPR_LEN {
            return Self::parse(src);
        }
        let chars: Vec<char> = src.chars().collect();
        Parser::whole(&chars, tables)
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
        self.compile_with(constant, inputs, &Arc::new(Tables::default()))
    }

    /// [`compile`](Self::compile) where the lookup tables `tables` may be called.
    pub fn compile_with(
        &self,
        constant: &dyn Fn(&str) -> Option<f64>,
        inputs: &[String],
        tables: &Arc<Tables>,
    ) -> Result<Compiled, String> {
        Ok(Compiled {
            root: self.lower(constant, inputs, tables)?,
            tables: Arc::clone(tables),
            n_inputs: inputs.len(),
        })
    }

    fn lower(
        &self,
        constant: &dyn Fn(&str) -> Option<f64>,
        inputs: &[String],
        tables: &Tables,
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
            Self::Neg(a) => Node::Neg(Box::new(a.lower(constant, inputs, tables)?)),
            Self::Bin(op, a, b) => Node::Bin(
                Op::of(*op),
                Box::new(a.lower(constant, inputs, tables)?),
                Box::new(b.lower(constant, inputs, tables)?),
            ),
            Self::Call(f, args) => {
                let func = tables
                    .index(f)
                    .map(Func::Table)
                    .or_else(|| Func::of(f))
                    .ok_or_else(|| format!("unknown function `{f}`"))?;
                Node::Call(
                    func,
                    args.iter()
                        .map(|a| a.lower(constant, inputs, tables))
                        .collect::<Result<_, _>>()?,
                )
            }
        })
    }
}

/// A binary operator, lowered from its character.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

impl Op {
    fn of(c: char) -> Self {
        match c {
            '+' => Self::Add,
            '-' => Self::Sub,
            '*' => Self::Mul,
            '/' => Self::Div,
            _ => Self::Pow,
        }
    }
    fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Self::Add => a + b,
            Self::Sub => a - b,
            Self::Mul => a * b,
            Self::Div => a / b,
            Self::Pow => a.powf(b),
        }
    }
}

fn binary(op: char, a: f64, b: f64) -> f64 {
    Op::of(op).apply(a, b)
}

/// A function, lowered from its name once at compile time (no string work in the rhs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Func {
    Sqrt,
    Exp,
    Ln,
    Log10,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Sinh,
    Cosh,
    Tanh,
    Abs,
    Sign,
    Step,
    Pow,
    Min,
    Max,
    Clamp,
    Deg,
    Rad,
    /// Lookup table `k` of the model's [`Tables`].
    Table(usize),
}

impl Func {
    fn of(name: &str) -> Option<Self> {
        Some(match name {
            "sqrt" => Self::Sqrt,
            "exp" => Self::Exp,
            "ln" => Self::Ln,
            "log10" => Self::Log10,
            "sin" => Self::Sin,
            "cos" => Self::Cos,
            "tan" => Self::Tan,
            "asin" => Self::Asin,
            "acos" => Self::Acos,
            "atan" => Self::Atan,
            "atan2" => Self::Atan2,
            "sinh" => Self::Sinh,
            "cosh" => Self::Cosh,
            "tanh" => Self::Tanh,
            "abs" => Self::Abs,
            "sign" => Self::Sign,
            "step" => Self::Step,
            "pow" => Self::Pow,
            "min" => Self::Min,
            "max" => Self::Max,
            "clamp" => Self::Clamp,
            "deg" => Self::Deg,
            "rad" => Self::Rad,
            _ => return None,
        })
    }

    /// The value at `v`; with `d`, the partial derivative with respect to each argument
    /// (exact; at a kink, one side's).
    fn apply(self, v: &[f64], tables: &Tables, d: Option<&mut [f64]>) -> f64 {
        let x = v[0];
        let (value, slope): (f64, f64) = match self {
            Self::Sqrt => (x.sqrt(), 0.5 / x.sqrt()),
            Self::Exp => (x.exp(), x.exp()),
            Self::Ln => (x.ln(), 1.0 / x),
            Self::Log10 => (x.log10(), 1.0 / (x * std::f64::consts::LN_10)),
            Self::Sin => (x.sin(), x.cos()),
            Self::Cos => (x.cos(), -x.sin()),
            Self::Tan => (x.tan(), 1.0 + x.tan() * x.tan()),
            Self::Asin => (x.asin(), 1.0 / (1.0 - x * x).sqrt()),
            Self::Acos => (x.acos(), -1.0 / (1.0 - x * x).sqrt()),
            Self::Atan => (x.atan(), 1.0 / (1.0 + x * x)),
            Self::Sinh => (x.sinh(), x.cosh()),
            Self::Cosh => (x.cosh(), x.sinh()),
            Self::Tanh => (x.tanh(), 1.0 - x.tanh() * x.tanh()),
            Self::Abs => (x.abs(), if x >= 0.0 { 1.0 } else { -1.0 }),
            Self::Sign => (
                if x > 0.0 {
                    1.0
                } else if x < 0.0 {
                    -1.0
                } else {
                    0.0
                },
                0.0,
            ),
            Self::Step => (if x >= 0.0 { 1.0 } else { 0.0 }, 0.0),
            Self::Deg => (x.to_degrees(), 180.0 / std::f64::consts::PI),
            Self::Rad => (x.to_radians(), std::f64::consts::PI / 180.0),
            Self::Atan2 => {
                let (y, x) = (v[0], v[1]);
                if let Some(d) = d {
                    let r2 = x * x + y * y;
                    d[0] = x / r2;
                    d[1] = -y / r2;
                }
                return y.atan2(x);
            }
            Self::Pow => {
                let (a, b) = (v[0], v[1]);
                let p = a.powf(b);
                if let Some(d) = d {
                    d[0] = b * a.powf(b - 1.0);
                    d[1] = if p == 0.0 { 0.0 } else { p * a.ln() };
                }
                return p;
            }
            Self::Min | Self::Max => {
                let mut k = 0;
                for (j, w) in v.iter().enumerate() {
                    let better = if self == Self::Min {
                        *w < v[k]
                    } else {
                        *w > v[k]
                    };
                    if better || w.is_nan() {
                        k = j;
                    }
                }
                if let Some(d) = d {
                    d.iter_mut().for_each(|x| *x = 0.0);
                    d[k] = 1.0;
                }
                return v[k];
            }
            Self::Clamp => {
                // bounds in the wrong order give NaN, which the run reports, not a silent `hi`
                if v[1] > v[2] {
                    return f64::NAN;
                }
                let k = if v[0] < v[1] {
                    1
                } else if v[0] > v[2] {
                    2
                } else {
                    0
                };
                if let Some(d) = d {
                    d[..3].iter_mut().for_each(|x| *x = 0.0);
                    d[k] = 1.0;
                }
                return v[k];
            }
            Self::Table(k) => {
                let Some(t) = tables.list.get(k) else {
                    return f64::NAN;
                };
                let mut dd = [0.0; 2];
                let value = t.eval(v, &mut dd);
                if let Some(d) = d {
                    let n = d.len().min(2);
                    d[..n].copy_from_slice(&dd[..n]);
                }
                return value;
            }
        };
        if let Some(d) = d {
            d[0] = slope;
        }
        value
    }
}

fn call(f: &str, v: &[f64]) -> f64 {
    Func::of(f).map_or(f64::NAN, |func| func.apply(v, &Tables::default(), None))
}

#[derive(Clone, Debug)]
enum Node {
    Num(f64),
    Input(usize),
    Neg(Box<Node>),
    Bin(Op, Box<Node>, Box<Node>),
    Call(Func, Vec<Node>),
}

/// Most arguments of a function call (`min`, `max`).
const MAX_ARGS: usize = 8;

/// Most inputs whose gradient [`Compiled::eval_grad`] carries without allocating.
pub const MAX_GRAD_INPUTS: usize = bondgraph::element::MAX_PARAM_INPUTS;

/// A compiled expression: constants folded in, functions lowered to an enum, signals read
/// from an input slice, lookup tables shared.
#[derive(Clone, Debug)]
pub struct Compiled {
    root: Node,
    tables: Arc<Tables>,
    n_inputs: usize,
}

impl Compiled {
    /// Evaluate with the inputs in the order given to [`Expr::compile`].
    #[must_use]
    pub fn eval(&self, inputs: &[f64]) -> f64 {
        eval_node(&self.root, inputs, &self.tables)
    }
    /// The value if the expression reads no inputs (it may still be NaN or infinite).
    #[must_use]
    pub fn constant(&self) -> Option<f64> {
        (!reads_inputs(&self.root)).then(|| eval_node(&self.root, &[], &self.tables))
    }
    /// The value and, in `grad`, its exact gradient with respect to the inputs (forward
    /// mode, no allocation; at a kink such as `abs`, `min` or a table's knot, one side's).
    /// `grad` has one entry per input, at most [`MAX_GRAD_INPUTS`].
    pub fn eval_grad(&self, inputs: &[f64], grad: &mut [f64]) -> f64 {
        let n = grad.len().min(MAX_GRAD_INPUTS);
        grad_node(&self.root, inputs, &self.tables, &mut grad[..n])
    }
    /// Whether [`eval_grad`](Self::eval_grad) can carry this expression's gradient.
    #[must_use]
    pub fn has_exact_gradient(&self) -> bool {
        self.n_inputs <= MAX_GRAD_INPUTS
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

/// The value of `n`. Leaves are read in place rather than through a call, and a function
/// call's argument buffer lives in [`eval_call`]: the same operations in the same order, in
/// a smaller recursion (the crane's run: 14.5 → 12.6 M instructions of evaluation).
fn eval_node(n: &Node, u: &[f64], tables: &Tables) -> f64 {
    match n {
        Node::Num(v) => *v,
        Node::Input(i) => u[*i],
        Node::Neg(a) => -eval_operand(a, u, tables),
        Node::Bin(op, a, b) => {
            let a = eval_operand(a, u, tables);
            op.apply(a, eval_operand(b, u, tables))
        }
        Node::Call(f, args) => eval_call(*f, args, u, tables),
    }
}

/// An operand: a leaf at once, any other node by [`eval_node`].
#[inline(always)]
fn eval_operand(n: &Node, u: &[f64], tables: &Tables) -> f64 {
    match n {
        Node::Num(v) => *v,
        Node::Input(i) => u[*i],
        _ => eval_node(n, u, tables),
    }
}

#[inline(never)]
fn eval_call(f: Func, args: &[Node], u: &[f64], tables: &Tables) -> f64 {
    let mut buf = [0.0; MAX_ARGS];
    let n = args.len().min(MAX_ARGS);
    for (k, a) in args.iter().take(n).enumerate() {
        buf[k] = eval_operand(a, u, tables);
    }
    f.apply(&buf[..n], tables, None)
}

/// Value of `n` and its gradient into `g` (zeroed here).
fn grad_node(n: &Node, u: &[f64], tables: &Tables, g: &mut [f64]) -> f64 {
    let m = g.len();
    match n {
        Node::Num(v) => {
            g.iter_mut().for_each(|x| *x = 0.0);
            *v
        }
        Node::Input(i) => {
            g.iter_mut().for_each(|x| *x = 0.0);
            if *i < m {
                g[*i] = 1.0;
            }
            u[*i]
        }
        Node::Neg(a) => {
            let v = grad_node(a, u, tables, g);
            g.iter_mut().for_each(|x| *x = -*x);
            -v
        }
        Node::Bin(op, a, b) => {
            let mut gb = [0.0; MAX_GRAD_INPUTS];
            let gb = &mut gb[..m];
            let va = grad_node(a, u, tables, g);
            let vb = grad_node(b, u, tables, gb);
            let v = op.apply(va, vb);
            match op {
                Op::Add => g.iter_mut().zip(gb.iter()).for_each(|(x, y)| *x += y),
                Op::Sub => g.iter_mut().zip(gb.iter()).for_each(|(x, y)| *x -= y),
                Op::Mul => g
                    .iter_mut()
                    .zip(gb.iter())
                    .for_each(|(x, y)| *x = vb * *x + va * y),
                Op::Div => g
                    .iter_mut()
                    .zip(gb.iter())
                    .for_each(|(x, y)| *x = (*x - v * y) / vb),
                Op::Pow => {
                    let da = vb * va.powf(vb - 1.0);
                    g.iter_mut().zip(gb.iter()).for_each(|(x, y)| {
                        // the exponent's term only where it varies (a constant exponent of
                        // a negative base is fine: ln is not taken)
                        let by_b = if *y == 0.0 || v == 0.0 {
                            0.0
                        } else {
                            v * va.ln() * y
                        };
                        *x = if *x == 0.0 { 0.0 } else { da * *x } + by_b;
                    });
                }
            }
            v
        }
        Node::Call(f, args) => {
            let k = args.len().min(MAX_ARGS);
            let mut vals = [0.0; MAX_ARGS];
            for (j, a) in args.iter().take(k).enumerate() {
                vals[j] = eval_node(a, u, tables);
            }
            let mut d = [0.0; MAX_ARGS];
            let v = f.apply(&vals[..k], tables, Some(&mut d[..k]));
            g.iter_mut().for_each(|x| *x = 0.0);
            let mut ga = [0.0; MAX_GRAD_INPUTS];
            let ga = &mut ga[..m];
            for (j, a) in args.iter().take(k).enumerate() {
                if d[j] == 0.0 || !reads_inputs(a) {
                    continue;
                }
                let _ = grad_node(a, u, tables, ga);
                g.iter_mut()
                    .zip(ga.iter())
                    .for_each(|(x, y)| *x += d[j] * y);
            }
            v
        }
    }
}

#[cfg(test)]
mod tests;
