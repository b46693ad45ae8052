//! The recursive-descent parser of [`Expr`] (depth bounded: a deeply nested expression is
//! refused, not a stack overflow).

use super::{Expr, ExprError, FUNCTIONS, MAX_EXPR_DEPTH};

/// `clamp(x, lo, hi)`: refuse the arguments in an order that cannot be meant: constant
/// bounds with lo > hi, or a constant first argument with a variable last one
/// (`clamp(0, 1, x)` for `clamp(x, 0, 1)`).
fn check_clamp(name: &str, args: &[Expr], start: usize) -> Result<(), ExprError> {
    if name != "clamp" || args.len() != 3 {
        return Ok(());
    }
    let constant = |e: &Expr| e.names().iter().all(|n| n == "pi");
    let value = |e: &Expr| e.eval(&|_| None).ok();
    let msg = if let (Some(lo), Some(hi)) = (value(&args[1]), value(&args[2])) {
        (lo > hi).then(|| format!("`clamp(x, lo, hi)` has lo = {lo} > hi = {hi}"))
    } else if constant(&args[0]) && !constant(&args[2]) {
        Some("`clamp(x, lo, hi)` takes the value first, then the bounds: the first argument is a constant and the last is not (did you mean `clamp(x, lo, hi)` for `clamp(lo, hi, x)`?)".to_owned())
    } else {
        None
    };
    msg.map_or(Ok(()), |message| {
        Err(ExprError {
            pos: start,
            message,
        })
    })
}

pub(super) struct Parser<'a> {
    c: &'a [char],
    /// Lookup tables callable as functions: name and number of arguments.
    tables: &'a [(String, usize)],
    i: usize,
    /// Current recursion depth of the parser.
    nest: usize,
}

/// An expression and its depth.
type Parsed = (Expr, usize);

impl<'a> Parser<'a> {
    /// All of `chars` as one expression.
    pub(super) fn whole(
        chars: &'a [char],
        tables: &'a [(String, usize)],
    ) -> Result<Expr, ExprError> {
        let mut p = Parser {
            c: chars,
            tables,
            i: 0,
            nest: 0,
        };
        let (e, _) = p.sum()?;
        p.ws();
        if p.i < chars.len() {
            return Err(p.err(format!("unexpected `{}`", chars[p.i])));
        }
        Ok(e)
    }

    fn err(&self, message: String) -> ExprError {
        ExprError {
            pos: self.i,
            message,
        }
    }
    fn too_deep(&self) -> ExprError {
        self.err(format!(
            "the expression is nested more than {MAX_EXPR_DEPTH} levels deep (parentheses, signs, calls, operators); split it into named parameters"
        ))
    }
    /// One level deeper into the parser; refused past [`MAX_EXPR_DEPTH`].
    fn enter(&mut self) -> Result<(), ExprError> {
        self.nest += 1;
        if self.nest > MAX_EXPR_DEPTH {
            return Err(self.too_deep());
        }
        Ok(())
    }
    /// A node over children of depth `d`, refused past [`MAX_EXPR_DEPTH`].
    fn node(&self, e: Expr, d: usize) -> Result<Parsed, ExprError> {
        if d + 1 > MAX_EXPR_DEPTH {
            return Err(self.too_deep());
        }
        Ok((e, d + 1))
    }
    fn ws(&mut self) {
        while self.i < self.c.len() && self.c[self.i].is_whitespace() {
            self.i += 1;
        }
    }
    fn peek(&mut self) -> Option<char> {
        self.ws();
        self.c.get(self.i).copied()
    }
    fn sum(&mut self) -> Result<Parsed, ExprError> {
        self.enter()?;
        let (mut a, mut da) = self.product()?;
        while let Some(op @ ('+' | '-')) = self.peek() {
            self.i += 1;
            let (b, db) = self.product()?;
            (a, da) = self.node(Expr::Bin(op, Box::new(a), Box::new(b)), da.max(db))?;
        }
        self.nest -= 1;
        Ok((a, da))
    }
    fn product(&mut self) -> Result<Parsed, ExprError> {
        let (mut a, mut da) = self.unary()?;
        while let Some(op @ ('*' | '/')) = self.peek() {
            self.i += 1;
            let (b, db) = self.unary()?;
            (a, da) = self.node(Expr::Bin(op, Box::new(a), Box::new(b)), da.max(db))?;
        }
        Ok((a, da))
    }
    fn unary(&mut self) -> Result<Parsed, ExprError> {
        let sign = self.peek();
        if !matches!(sign, Some('-' | '+')) {
            return self.power();
        }
        self.i += 1;
        self.enter()?;
        let (a, d) = self.unary()?;
        self.nest -= 1;
        if sign == Some('-') {
            self.node(Expr::Neg(Box::new(a)), d)
        } else {
            Ok((a, d))
        }
    }
    fn power(&mut self) -> Result<Parsed, ExprError> {
        let (base, db) = self.atom()?;
        if self.peek() == Some('^') {
            self.i += 1;
            let (exp, de) = self.unary()?;
            return self.node(Expr::Bin('^', Box::new(base), Box::new(exp)), db.max(de));
        }
        Ok((base, db))
    }
    fn atom(&mut self) -> Result<Parsed, ExprError> {
        match self.peek() {
            None => Err(self.err("expression ends too early".into())),
            Some('(') => {
                self.i += 1;
                let e = self.sum()?;
                if self.peek() != Some(')') {
                    return Err(self.err("missing `)`".into()));
                }
                self.i += 1;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => Ok((self.number()?, 1)),
            Some(c) if c.is_alphabetic() || c == '_' => self.name(),
            Some(c) => Err(self.err(format!("unexpected `{c}`"))),
        }
    }
    fn number(&mut self) -> Result<Expr, ExprError> {
        let start = self.i;
        while self.i < self.c.len()
            && (self.c[self.i].is_ascii_digit() || self.c[self.i] == '.' || self.c[self.i] == '_')
        {
            self.i += 1;
        }
        if self.i < self.c.len() && (self.c[self.i] == 'e' || self.c[self.i] == 'E') {
            let save = self.i;
            self.i += 1;
            if self.i < self.c.len() && (self.c[self.i] == '+' || self.c[self.i] == '-') {
                self.i += 1;
            }
            let digits = self.i;
            while self.i < self.c.len() && self.c[self.i].is_ascii_digit() {
                self.i += 1;
            }
            if self.i == digits {
                self.i = save;
            }
        }
        let s: String = self.c[start..self.i]
            .iter()
            .filter(|&&c| c != '_')
            .collect();
        s.parse().map(Expr::Num).map_err(|_| ExprError {
            pos: start,
            message: format!("`{}` is not a number", crate::error::clip(&s)),
        })
    }
    fn name(&mut self) -> Result<Parsed, ExprError> {
        let start = self.i;
        while self.i < self.c.len()
            && (self.c[self.i].is_alphanumeric() || self.c[self.i] == '_' || self.c[self.i] == '.')
        {
            self.i += 1;
        }
        // an index suffix `[k]`
        if self.i < self.c.len() && self.c[self.i] == '[' {
            let save = self.i;
            self.i += 1;
            while self.i < self.c.len() && self.c[self.i].is_ascii_digit() {
                self.i += 1;
            }
            if self.i < self.c.len() && self.c[self.i] == ']' {
                self.i += 1;
            } else {
                self.i = save;
            }
        }
        let name: String = self.c[start..self.i].iter().collect();
        if name.ends_with('.') {
            return Err(ExprError {
                pos: start,
                message: format!("`{}` is not a valid name", crate::error::clip(&name)),
            });
        }
        if self.peek() == Some('(') {
            let table = self
                .tables
                .iter()
                .find(|(t, _)| *t == name)
                .map(|(_, n)| Some(*n));
            let builtin = FUNCTIONS.iter().find(|(f, _)| *f == name).map(|(_, a)| *a);
            let Some(arity) = table.or(builtin) else {
                let mut known: Vec<&str> = FUNCTIONS.iter().map(|(f, _)| *f).collect();
                known.extend(self.tables.iter().map(|(t, _)| t.as_str()));
                return Err(ExprError {
                    pos: start,
                    message: format!(
                        "unknown function `{}`; known: {}",
                        crate::error::clip(&name),
                        known.join(", ")
                    ),
                });
            };
            self.i += 1;
            let mut args = Vec::new();
            let mut depth = 0;
            if self.peek() != Some(')') {
                loop {
                    let (a, d) = self.sum()?;
                    args.push(a);
                    depth = depth.max(d);
                    match self.peek() {
                        Some(',') => self.i += 1,
                        Some(')') => break,
                        _ => return Err(self.err("expected `,` or `)`".into())),
                    }
                }
            }
            self.i += 1;
            let ok = match arity {
                Some(n) => args.len() == n,
                None => !args.is_empty() && args.len() <= 8,
            };
            if !ok {
                return Err(ExprError {
                    pos: start,
                    message: format!(
                        "`{name}` takes {} argument(s), got {}",
                        arity.map_or("1 to 8".into(), |n| n.to_string()),
                        args.len()
                    ),
                });
            }
            check_clamp(&name, &args, start)?;
            return self.node(Expr::Call(name, args), depth);
        }
        Ok((Expr::Name(name), 1))
    }
}
