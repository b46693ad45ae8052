//! Stage 2, resolve: the `[parameters]` evaluated (numbers and expressions of each other,
//! in any order), with the values `--set` wrote into the text ([`crate::overrides`]) or an
//! event sets. Every parameter is tried: one that fails is reported once, and those that use
//! it are not reported again.

use std::collections::HashSet;

use indexmap::IndexMap;

use super::source::Source;
use crate::error::{clip, ErrorKind, ModelError};
use crate::expr::Expr;
use crate::reader::RawValue;
use bondgraph::kind::units;

/// A parameter being evaluated: its expression, the names it uses and the next to look at.
struct PendingParam {
    name: String,
    expr: Expr,
    names: Vec<String>,
    next: usize,
}

/// Why a parameter has no value: its own problem, or one reported already.
type Failure = Option<ModelError>;

/// `"300 bar"`: the expression converted to SI (`1e5 * 300`), the unit and its text; `None`
/// for a value without a unit.
fn with_unit(s: &str) -> Option<(Expr, units::Unit, &str)> {
    let (body, unit) = units::split_value(s)?;
    let e = Expr::parse(body).ok()?;
    let text = units::split_last(s).map_or("", |(_, u)| u);
    Some((
        Expr::Bin('*', Box::new(Expr::Num(unit.scale)), Box::new(e)),
        unit,
        text,
    ))
}

impl Source {
    /// The `[parameters]` written with a unit: name → (unit, its text).
    pub(super) fn units_of_parameters(&self) -> crate::reader::ParamUnits {
        self.param_exprs
            .iter()
            .filter_map(|(k, raw)| match &raw.value {
                toml::Value::String(s) => {
                    with_unit(s).map(|(_, u, text)| (k.clone(), (u, text.to_owned())))
                }
                _ => None,
            })
            .collect()
    }

    /// Every named parameter, with `set` overriding some expressions; the first problem.
    pub(super) fn evaluate_parameters(
        &self,
        set: &IndexMap<String, RawValue>,
    ) -> Result<IndexMap<String, f64>, ModelError> {
        let (values, mut problems, _) = self.evaluate_all(set);
        if problems.is_empty() {
            Ok(values)
        } else {
            Err(problems.remove(0))
        }
    }

    /// Every named parameter that has a value (in file order), with `set` overriding some
    /// expressions; the problems, and the names that have no value.
    pub(super) fn evaluate_all(
        &self,
        set: &IndexMap<String, RawValue>,
    ) -> (IndexMap<String, f64>, Vec<ModelError>, HashSet<String>) {
        let mut exprs: IndexMap<String, RawValue> = self.param_exprs.clone();
        for (k, v) in set {
            exprs.insert(k.clone(), v.clone());
        }
        let mut values: IndexMap<String, f64> = IndexMap::new();
        let mut failed = HashSet::new();
        let mut problems = Vec::new();
        for name in exprs.keys() {
            if let Err(Some(e)) = self.eval_param(name, &exprs, &mut values, &mut failed) {
                problems.push(e);
            }
        }
        // keep file order
        let ordered = exprs
            .keys()
            .filter_map(|n| values.get(n).map(|v| (n.clone(), *v)))
            .collect();
        (ordered, problems, failed)
    }

    /// The parsed expression of parameter `name` and the names it uses.
    fn parse_param(
        &self,
        name: &str,
        exprs: &IndexMap<String, RawValue>,
    ) -> Result<PendingParam, ModelError> {
        let raw = &exprs[name];
        let expr = match &raw.value {
            toml::Value::Float(v) => Expr::Num(*v),
            toml::Value::Integer(i) => Expr::Num(*i as f64),
            toml::Value::String(s) => with_unit(s).map_or_else(
                || {
                    Expr::parse(s).map_err(|e| {
                        let e = self.err(
                            ErrorKind::BadParameter,
                            Some(&raw.span),
                            format!("parameter `{name}` = \"{}\": {e}", clip(s)),
                        );
                        // a number or expression followed by a word that is no unit
                        match units::split_last(s) {
                            Some((body, word)) if Expr::parse(body).is_ok() => {
                                let (message, hint) = units::why_not(word);
                                let mut e = e.hint(hint);
                                e.message =
                                    format!("parameter `{name}` = \"{}\": {message}", clip(s));
                                e
                            }
                            _ => e,
                        }
                    })
                },
                |(e, _, _)| Ok(e),
            )?,
            other => {
                return Err(self.err(
                    ErrorKind::BadParameter,
                    Some(&raw.span),
                    format!(
                        "parameter `{name}` must be a number or an expression string, not {}",
                        other.type_str()
                    ),
                ));
            }
        };
        Ok(PendingParam {
            name: name.to_owned(),
            names: expr.names(),
            expr,
            next: 0,
        })
    }

    /// Evaluate parameter `root` and those it uses; on failure `root` and every parameter on
    /// the way to the culprit go into `failed`.
    fn eval_param(
        &self,
        root: &str,
        exprs: &IndexMap<String, RawValue>,
        values: &mut IndexMap<String, f64>,
        failed: &mut HashSet<String>,
    ) -> Result<(), Failure> {
        if values.contains_key(root) || failed.contains(root) {
            return Ok(());
        }
        let mut stack = Vec::new();
        let r = self.eval_stack(root, exprs, values, failed, &mut stack);
        if r.is_err() {
            failed.insert(root.to_owned());
            failed.extend(stack.into_iter().map(|p| p.name));
        }
        r
    }

    /// Depth first with an explicit stack (a chain of 100 000 parameters must not overflow
    /// the call stack).
    fn eval_stack(
        &self,
        root: &str,
        exprs: &IndexMap<String, RawValue>,
        values: &mut IndexMap<String, f64>,
        failed: &mut HashSet<String>,
        stack: &mut Vec<PendingParam>,
    ) -> Result<(), Failure> {
        stack.push(self.parse_param(root, exprs)?);
        let mut on_stack: HashSet<String> = HashSet::from([root.to_owned()]);
        while let Some(top) = stack.last_mut() {
            if let Some(n) = top.names.get(top.next).cloned() {
                top.next += 1;
                if n == "pi" || values.contains_key(&n) {
                    continue;
                }
                if failed.contains(&n) {
                    return Err(None);
                }
                let name = &top.name;
                if !exprs.contains_key(&n) {
                    return Err(Some(
                        self.err(
                            ErrorKind::BadParameter,
                            Some(&exprs[name].span),
                            format!(
                                "parameter `{name}` uses `{}`, which is not a parameter",
                                clip(&n)
                            ),
                        )
                        .hint(format!(
                            "parameters may only use numbers and other parameters; known: {}",
                            clip(&exprs.keys().cloned().collect::<Vec<_>>().join(", "))
                        )),
                    ));
                }
                if on_stack.contains(&n) {
                    let chain: Vec<&str> = stack.iter().map(|p| p.name.as_str()).collect();
                    return Err(Some(
                        self.err(
                            ErrorKind::BadParameter,
                            Some(&exprs[&n].span),
                            clip(&format!(
                                "parameter `{n}` depends on itself: {} -> {n}",
                                chain.join(" -> ")
                            )),
                        )
                        .hint("break the cycle: give one of these parameters a number"),
                    ));
                }
                on_stack.insert(n.clone());
                let p = self.parse_param(&n, exprs).inspect_err(|_| {
                    failed.insert(n.clone());
                })?;
                stack.push(p);
                continue;
            }
            let Some(done) = stack.pop() else { break };
            on_stack.remove(&done.name);
            let span = &exprs[&done.name].span;
            let v = match done.expr.eval(&|n| values.get(n).copied()) {
                Ok(v) => v,
                Err(m) => {
                    failed.insert(done.name);
                    return Err(Some(self.err(ErrorKind::BadParameter, Some(span), m)));
                }
            };
            if !v.is_finite() {
                let e = self
                    .err(
                        ErrorKind::BadParameter,
                        Some(span),
                        format!("parameter `{}` is {v}, which is not finite", done.name),
                    )
                    .hint("check for division by zero, a negative square root or a typo");
                failed.insert(done.name);
                return Err(Some(e));
            }
            values.insert(done.name, v);
        }
        Ok(())
    }
}
