//! The declarations: a kind's parameters ([`ParamDecl`]) and the kind itself ([`KindDecl`]).

use std::fmt;

use super::composite::Composite;
use super::params::{BuildError, Params};
use crate::Element;

/// What a parameter's value is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamType {
    /// A constant number: a number or an expression of the model's parameters.
    Number,
    /// A number that may also read signals and time (`"1 + 0.1*spring.q"`): a [`crate::Param`].
    Modulated,
    /// A whole number ≥ 0 (mode counts, quadrature points).
    Count,
    /// The name of a signal (`"spring.q"`, `"t"`).
    Signal,
    /// `true` or `false`.
    Flag,
    /// One of the listed words.
    Choice(&'static [&'static str]),
    /// A list of constant numbers (one number is a list of one).
    Vector,
    /// An array of equal-length rows of (possibly modulated) expressions.
    Matrix,
    /// One nested table, declared by the given parameters.
    Table(&'static [ParamDecl]),
    /// A list of nested tables, each declared by the given parameters.
    Tables(&'static [ParamDecl]),
}

impl ParamType {
    /// A short name for tables and errors.
    #[must_use]
    pub fn describe(&self) -> &'static str {
        match self {
            Self::Number => "number",
            Self::Modulated => "number or signal expression",
            Self::Count => "whole number",
            Self::Signal => "signal name",
            Self::Flag => "true/false",
            Self::Choice(_) => "word",
            Self::Vector => "list of numbers",
            Self::Matrix => "matrix",
            Self::Table(_) => "table",
            Self::Tables(_) => "list of tables",
        }
    }
}

/// What happens when a parameter is not given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Default {
    /// It must be given.
    Required,
    /// This number.
    Value(f64),
    /// This word (a [`ParamType::Choice`]).
    Word(&'static str),
    /// This flag.
    Flag(bool),
    /// Nothing: the builder sees `None` and does what the text says ("1e-3·A·l⁰",
    /// "no end stop"); also for alternatives such as `alpha` or `cd, w, rho`.
    Optional(&'static str),
}

impl fmt::Display for Default {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Required => write!(f, "required"),
            Self::Value(v) if v.is_infinite() => write!(f, "{}∞", if *v < 0.0 { "−" } else { "" }),
            Self::Value(v) => write!(f, "{}", number(*v)),
            Self::Word(w) => write!(f, "\"{w}\""),
            Self::Flag(b) => write!(f, "{b}"),
            Self::Optional("") => write!(f, "none"),
            Self::Optional(s) => write!(f, "{s}"),
        }
    }
}

/// A number as people write it: `0.5`, `250`, `1e5`, `1.5e9`, `2e-6`.
#[must_use]
pub fn number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-3..1e5).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// The values a number may take: `lo ≤ (or <) x ≤ (or <) hi`, and always finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// Lower bound (−∞: none).
    pub lo: f64,
    /// Upper bound (+∞: none).
    pub hi: f64,
    /// Whether `lo` itself is excluded.
    pub lo_open: bool,
    /// Whether `hi` itself is excluded.
    pub hi_open: bool,
}

impl Range {
    /// Any finite number.
    pub const ANY: Self = Self {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
        lo_open: true,
        hi_open: true,
    };
    /// `> 0`.
    pub const POSITIVE: Self = Self {
        lo: 0.0,
        lo_open: true,
        ..Self::ANY
    };
    /// `≥ 0`.
    pub const NON_NEGATIVE: Self = Self {
        lo: 0.0,
        lo_open: false,
        ..Self::ANY
    };
    /// `[0, 1]`.
    pub const FRACTION: Self = Self {
        lo: 0.0,
        hi: 1.0,
        lo_open: false,
        hi_open: false,
    };

    /// `[lo, hi]`.
    #[must_use]
    pub const fn closed(lo: f64, hi: f64) -> Self {
        Self {
            lo,
            hi,
            lo_open: false,
            hi_open: false,
        }
    }
    /// `≥ lo`.
    #[must_use]
    pub const fn at_least(lo: f64) -> Self {
        Self {
            lo,
            lo_open: false,
            ..Self::ANY
        }
    }
    /// `> lo`.
    #[must_use]
    pub const fn above(lo: f64) -> Self {
        Self {
            lo,
            lo_open: true,
            ..Self::ANY
        }
    }

    /// Whether `x` is finite and inside.
    #[must_use]
    pub fn contains(&self, x: f64) -> bool {
        x.is_finite()
            && (if self.lo_open {
                x > self.lo
            } else {
                x >= self.lo
            })
            && (if self.hi_open {
                x < self.hi
            } else {
                x <= self.hi
            })
    }

    /// Whether this is [`Range::ANY`].
    #[must_use]
    pub fn is_any(&self) -> bool {
        self.lo == f64::NEG_INFINITY && self.hi == f64::INFINITY
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (lo, hi) = (self.lo.is_finite(), self.hi.is_finite());
        match (lo, hi) {
            (false, false) => write!(f, "finite"),
            (true, false) => write!(
                f,
                "{} {}",
                if self.lo_open { ">" } else { ">=" },
                number(self.lo)
            ),
            (false, true) => write!(
                f,
                "{} {}",
                if self.hi_open { "<" } else { "<=" },
                number(self.hi)
            ),
            (true, true) => write!(
                f,
                "in {}{}, {}{}",
                if self.lo_open { "(" } else { "[" },
                number(self.lo),
                number(self.hi),
                if self.hi_open { ")" } else { "]" }
            ),
        }
    }
}

/// One parameter of a kind: Modelica's `parameter Real beta(unit="Pa") "bulk modulus"`.
///
/// Built with `const` constructors and modifiers so a kind's table is plain data:
/// `ParamDecl::number("beta", "Pa", "bulk modulus").positive()`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamDecl {
    /// The key in the model file.
    pub name: &'static str,
    /// What the value is.
    pub ty: ParamType,
    /// SI unit (`"Pa"`, `"m³/s"`, `"1"` for dimensionless, `""` for words and signals).
    pub unit: &'static str,
    /// What happens when it is not given.
    pub default: Default,
    /// Allowed values (numbers, counts and vectors' entries; modulated values are checked
    /// when constant).
    pub range: Range,
    /// One line of description.
    pub doc: &'static str,
    /// A modulated value that is a function of this variable (e.g. `x` along a link),
    /// which its expression may name besides parameters and signals; the builder evaluates
    /// it. `None`: parameters and signals only.
    pub variable: Option<&'static str>,
}

impl ParamDecl {
    const fn new(name: &'static str, ty: ParamType, unit: &'static str, doc: &'static str) -> Self {
        Self {
            name,
            ty,
            unit,
            default: Default::Required,
            range: Range::ANY,
            doc,
            variable: None,
        }
    }
    /// A required constant number.
    #[must_use]
    pub const fn number(name: &'static str, unit: &'static str, doc: &'static str) -> Self {
        Self::new(name, ParamType::Number, unit, doc)
    }
    /// A required number that may read signals and time.
    #[must_use]
    pub const fn modulated(name: &'static str, unit: &'static str, doc: &'static str) -> Self {
        Self::new(name, ParamType::Modulated, unit, doc)
    }
    /// A required whole number.
    #[must_use]
    pub const fn count(name: &'static str, doc: &'static str) -> Self {
        Self::new(name, ParamType::Count, "1", doc).range(Range::NON_NEGATIVE)
    }
    /// A required signal name.
    #[must_use]
    pub const fn signal(name: &'static str, unit: &'static str, doc: &'static str) -> Self {
        Self::new(name, ParamType::Signal, unit, doc)
    }
    /// A flag with its default.
    #[must_use]
    pub const fn flag(name: &'static str, default: bool, doc: &'static str) -> Self {
        Self::new(name, ParamType::Flag, "", doc).with_default(Default::Flag(default))
    }
    /// One of `choices`, `default` when absent.
    #[must_use]
    pub const fn choice(
        name: &'static str,
        choices: &'static [&'static str],
        default: &'static str,
        doc: &'static str,
    ) -> Self {
        Self::new(name, ParamType::Choice(choices), "", doc).with_default(Default::Word(default))
    }
    /// A list of constant numbers.
    #[must_use]
    pub const fn vector(name: &'static str, unit: &'static str, doc: &'static str) -> Self {
        Self::new(name, ParamType::Vector, unit, doc)
    }
    /// A matrix of expressions.
    #[must_use]
    pub const fn matrix(name: &'static str, unit: &'static str, doc: &'static str) -> Self {
        Self::new(name, ParamType::Matrix, unit, doc)
    }
    /// One nested table.
    #[must_use]
    pub const fn table(
        name: &'static str,
        fields: &'static [ParamDecl],
        doc: &'static str,
    ) -> Self {
        Self::new(name, ParamType::Table(fields), "", doc)
    }
    /// A list of nested tables.
    #[must_use]
    pub const fn tables(
        name: &'static str,
        fields: &'static [ParamDecl],
        doc: &'static str,
    ) -> Self {
        Self::new(name, ParamType::Tables(fields), "", doc)
    }

    /// Optional with this default value.
    #[must_use]
    pub const fn default(self, value: f64) -> Self {
        self.with_default(Default::Value(value))
    }
    /// Optional without a default; `meaning` says what absence does.
    #[must_use]
    pub const fn optional(self, meaning: &'static str) -> Self {
        self.with_default(Default::Optional(meaning))
    }
    /// A function of `variable`, which its expression may name ([`ParamDecl::variable`]).
    #[must_use]
    pub const fn of(mut self, variable: &'static str) -> Self {
        self.variable = Some(variable);
        self
    }
    /// With this [`Default`].
    #[must_use]
    pub const fn with_default(mut self, default: Default) -> Self {
        self.default = default;
        self
    }
    /// With this range.
    #[must_use]
    pub const fn range(mut self, range: Range) -> Self {
        self.range = range;
        self
    }
    /// `> 0`.
    #[must_use]
    pub const fn positive(self) -> Self {
        self.range(Range::POSITIVE)
    }
    /// `≥ 0`.
    #[must_use]
    pub const fn non_negative(self) -> Self {
        self.range(Range::NON_NEGATIVE)
    }

    /// Whether a model must give it.
    #[must_use]
    pub fn required(&self) -> bool {
        matches!(self.default, Default::Required)
    }

    /// The nested declarations of a table parameter.
    #[must_use]
    pub fn fields(&self) -> Option<&'static [ParamDecl]> {
        match self.ty {
            ParamType::Table(f) | ParamType::Tables(f) => Some(f),
            _ => None,
        }
    }
}

/// A builder of one element.
pub type ElementBuilder = fn(&dyn Params) -> Result<Box<dyn Element>, BuildError>;
/// A builder of a sub-graph.
pub type CompositeBuilder = fn(&dyn Params) -> Result<Composite, BuildError>;

/// How a kind is built: one element, or a sub-graph.
#[derive(Clone, Copy)]
pub enum Build {
    /// One element.
    Element(ElementBuilder),
    /// A sub-graph ([`Composite`]).
    Composite(CompositeBuilder),
}

impl fmt::Debug for Build {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Element(_) => "Build::Element",
            Self::Composite(_) => "Build::Composite",
        })
    }
}

/// One change a [`Simplification`] makes to the parameters of an instance of its kind,
/// written as a model file writes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Change {
    /// Set parameter `key` to `value` (TOML: `"0"`, `"1"`, `"\"rigid\""`). A key
    /// `list[*].key` sets `key` in every entry of the list of tables `list` that has it
    /// (`links[*].modes`: every beam).
    Set(&'static str, &'static str),
    /// Remove parameter `key`: the instance gets what its absence declares ("no internal
    /// leakage", "no dynamics").
    Unset(&'static str),
}

impl Change {
    /// The parameter it changes (`links[*].modes`, `r_int`).
    #[must_use]
    pub fn key(&self) -> &'static str {
        match self {
            Self::Set(k, _) | Self::Unset(k) => k,
        }
    }
}

impl fmt::Display for Change {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Set(k, v) => write!(f, "{k} = {v}"),
            Self::Unset(k) => write!(f, "no {k}"),
        }
    }
}

/// A simpler law an instance of a kind can be reduced to (the activity-based reduction of
/// Louca and Stein, MORA: an element whose share of the energy flow over a scene is small is
/// removed or simplified): a name, what it does, the members whose energy flow it removes,
/// and the parameter changes that make it. The reducer (`bg-sim reduce --by activity`)
/// applies the changes to the model file's entry without knowing the kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Simplification {
    /// A short name (`no_internal_leakage`, `rigid_lumped_masses`).
    pub name: &'static str,
    /// One line: what the simplified instance is.
    pub doc: &'static str,
    /// The members of a composite whose energy flow the simplification removes, by their
    /// local names (`leak`; [`super::member_name`] gives the global ones); empty: the whole
    /// element. The sum of their activity shares is what the reducer compares with its
    /// threshold, so it must bound the energy flow the simplification takes away.
    pub members: &'static [&'static str],
    /// The parameter changes, applied in order.
    pub changes: &'static [Change],
}

impl Simplification {
    /// A simplification of the whole element.
    #[must_use]
    pub const fn new(name: &'static str, doc: &'static str, changes: &'static [Change]) -> Self {
        Self {
            name,
            doc,
            members: &[],
            changes,
        }
    }
    /// Whose energy flow it removes: these members of the composite.
    #[must_use]
    pub const fn members(mut self, members: &'static [&'static str]) -> Self {
        self.members = members;
        self
    }
}

/// An element kind: its name in model files, one line of summary, its parameters, a builder,
/// the simplifications it can be reduced to, and a complete example of its parameters (what `bg-sim kinds NAME` builds to list ports,
/// states and published variables, and what the tests build).
#[derive(Clone, Copy, Debug)]
pub struct KindDecl {
    /// `"hydraulics.chamber"`.
    pub name: &'static str,
    /// One line: the law.
    pub summary: &'static str,
    /// Every parameter the kind reads.
    pub params: &'static [ParamDecl],
    /// The builder.
    pub build: Build,
    /// The parameters of a working instance, as a model file writes them inside `{ … }`
    /// (`"beta = 1.5e9, volume = 1e-3"`); signals it names are listed as inputs.
    pub example: &'static str,
    /// What an instance can be simplified to ([`Simplification`]), richest first.
    pub simplifications: &'static [Simplification],
}

impl KindDecl {
    /// A kind that builds one element.
    #[must_use]
    pub const fn element(
        name: &'static str,
        summary: &'static str,
        params: &'static [ParamDecl],
        build: ElementBuilder,
    ) -> Self {
        Self {
            name,
            summary,
            params,
            build: Build::Element(build),
            example: "",
            simplifications: &[],
        }
    }
    /// A kind that expands into a sub-graph.
    #[must_use]
    pub const fn composite(
        name: &'static str,
        summary: &'static str,
        params: &'static [ParamDecl],
        build: CompositeBuilder,
    ) -> Self {
        Self {
            name,
            summary,
            params,
            build: Build::Composite(build),
            example: "",
            simplifications: &[],
        }
    }
    /// With this example.
    #[must_use]
    pub const fn example(mut self, example: &'static str) -> Self {
        self.example = example;
        self
    }

    /// With these simplifications.
    #[must_use]
    pub const fn simplifications(mut self, simplifications: &'static [Simplification]) -> Self {
        self.simplifications = simplifications;
        self
    }

    /// The simplification called `name`.
    #[must_use]
    pub fn simplification(&self, name: &str) -> Option<&'static Simplification> {
        self.simplifications.iter().find(|s| s.name == name)
    }

    /// The declaration of parameter `name`.
    #[must_use]
    pub fn param(&self, name: &str) -> Option<&'static ParamDecl> {
        self.params.iter().find(|p| p.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_hold_their_bounds() {
        assert!(Range::POSITIVE.contains(1e-300));
        assert!(!Range::POSITIVE.contains(0.0));
        assert!(Range::NON_NEGATIVE.contains(0.0));
        assert!(!Range::NON_NEGATIVE.contains(-1e-300));
        assert!(!Range::ANY.contains(f64::NAN));
        assert!(!Range::ANY.contains(f64::INFINITY));
        assert!(Range::FRACTION.contains(1.0) && !Range::FRACTION.contains(1.0 + 1e-15));
        assert_eq!(Range::POSITIVE.to_string(), "> 0");
        assert_eq!(Range::closed(-1.0, 1.0).to_string(), "in [-1, 1]");
    }

    #[test]
    fn a_declaration_is_plain_data() {
        const D: ParamDecl = ParamDecl::number("beta", "Pa", "bulk modulus")
            .positive()
            .default(1.5e9);
        assert_eq!(D.name, "beta");
        assert_eq!(D.default, Default::Value(1.5e9));
        assert!(!D.required());
        assert_eq!(D.range, Range::POSITIVE);
        assert_eq!(Default::Value(1e5).to_string(), "1e5");
        assert_eq!(Default::Value(f64::NEG_INFINITY).to_string(), "−∞");
    }
}
