//! Units: a declared unit (`"Pa"`, `"m³/s"`, `"m³/(s·√Pa)"`) and a value written with one
//! (`"200 bar"`, `"40 L/min"`, `"30 deg"`) are read into a scale to SI and a dimension over
//! mass, length, time and angle, so that the loader converts `"200 bar"` to 2e7 Pa and
//! refuses `"3 m"` for a pressure.
//!
//! Grammar: `unit := factor (('·' | '*' | '/') factor)*`, `factor := ('√' factor | '(' unit
//! ')' | symbol) power?`, `power := '²' | '³' | '⁻¹' | '^' integer | digit`; `/` applies to
//! the factor right after it (`mm2` is mm², `m3/h` is m³/h).
//!
//! **Angle** is tracked as a dimension of its own although SI calls it dimensionless: its
//! factors matter (a revolution is 2π rad) and a value without one is usually meant per
//! revolution (a pump's "250 cc"). So `cc` (m³) and `cc/rev` (m³·rad⁻¹ · 1/2π) differ, rpm
//! and Hz are revolutions (cycles) per minute and second and convert to rad/s with their
//! 2π, and `1/min` is not an angular speed. `%` and `1` stay interchangeable (0.01 is a
//! factor nobody mistakes).
//!
//! Spelling: symbols are case-sensitive (`mN` and `MN` differ), but a symbol this table does
//! not know that matches exactly one of its symbols ignoring case is read as that one
//! (`Bar`, `RPM`, `ml`, `KPA`); a few common spellings are aliases (`lpm`, `psig`, `Nm`,
//! `µs`); the rest are refused by [`why_not`] with a suggestion.

/// Exponents of mass, length, time and angle, doubled (so √Pa is representable).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dim(pub [i32; 4]);

impl Dim {
    const NONE: Self = Self([0, 0, 0, 0]);
    fn times(self, o: Self, sign: i32) -> Self {
        Self(std::array::from_fn(|i| self.0[i] + sign * o.0[i]))
    }
    fn pow2(self, num: i32, den: i32) -> Option<Self> {
        let f = |e: i32| (e * num % den == 0).then_some(e * num / den);
        Some(Self([
            f(self.0[0])?,
            f(self.0[1])?,
            f(self.0[2])?,
            f(self.0[3])?,
        ]))
    }
    /// The same dimension without its angle.
    #[must_use]
    pub fn without_angle(self) -> Self {
        Self([self.0[0], self.0[1], self.0[2], 0])
    }
    /// The exponent of angle (1 for rad, −1 for per radian).
    #[must_use]
    pub fn angle(self) -> i32 {
        self.0[3] / 2
    }
}

/// A unit read: the factor to SI and its dimension.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unit {
    /// Multiply a value in this unit by `scale` to get SI.
    pub scale: f64,
    /// Its dimension.
    pub dim: Dim,
}

const TAU: f64 = std::f64::consts::TAU;
const A: i32 = 2; // one angle, doubled

/// Symbol, factor to SI, doubled exponents of kg, m, s, rad.
const SYMBOLS: &[(&str, f64, [i32; 4])] = &[
    ("1", 1.0, [0, 0, 0, 0]),
    ("%", 0.01, [0, 0, 0, 0]),
    ("rad", 1.0, [0, 0, 0, A]),
    ("deg", TAU / 360.0, [0, 0, 0, A]),
    ("°", TAU / 360.0, [0, 0, 0, A]),
    ("rev", TAU, [0, 0, 0, A]),
    ("m", 1.0, [0, 2, 0, 0]),
    ("km", 1e3, [0, 2, 0, 0]),
    ("cm", 1e-2, [0, 2, 0, 0]),
    ("mm", 1e-3, [0, 2, 0, 0]),
    ("µm", 1e-6, [0, 2, 0, 0]),
    ("um", 1e-6, [0, 2, 0, 0]),
    ("in", 0.0254, [0, 2, 0, 0]),
    ("ft", 0.3048, [0, 2, 0, 0]),
    ("s", 1.0, [0, 0, 2, 0]),
    ("ms", 1e-3, [0, 0, 2, 0]),
    ("µs", 1e-6, [0, 0, 2, 0]),
    ("us", 1e-6, [0, 0, 2, 0]),
    ("min", 60.0, [0, 0, 2, 0]),
    ("h", 3600.0, [0, 0, 2, 0]),
    ("Hz", TAU, [0, 0, -2, A]),
    ("rpm", TAU / 60.0, [0, 0, -2, A]),
    ("kg", 1.0, [2, 0, 0, 0]),
    ("g", 1e-3, [2, 0, 0, 0]),
    ("t", 1e3, [2, 0, 0, 0]),
    ("N", 1.0, [2, 2, -4, 0]),
    ("kN", 1e3, [2, 2, -4, 0]),
    ("MN", 1e6, [2, 2, -4, 0]),
    ("lbf", 4.448_221_615_260_5, [2, 2, -4, 0]),
    ("Pa", 1.0, [2, -2, -4, 0]),
    ("kPa", 1e3, [2, -2, -4, 0]),
    ("MPa", 1e6, [2, -2, -4, 0]),
    ("GPa", 1e9, [2, -2, -4, 0]),
    ("bar", 1e5, [2, -2, -4, 0]),
    ("mbar", 1e2, [2, -2, -4, 0]),
    ("psi", 6_894.757_293_168, [2, -2, -4, 0]),
    ("atm", 101_325.0, [2, -2, -4, 0]),
    ("J", 1.0, [2, 4, -4, 0]),
    ("kJ", 1e3, [2, 4, -4, 0]),
    ("W", 1.0, [2, 4, -6, 0]),
    ("kW", 1e3, [2, 4, -6, 0]),
    ("L", 1e-3, [0, 6, 0, 0]),
    ("l", 1e-3, [0, 6, 0, 0]),
    ("mL", 1e-6, [0, 6, 0, 0]),
    ("cc", 1e-6, [0, 6, 0, 0]),
];

/// Common spellings read as a unit of the table: (spelling, unit).
const ALIASES: &[(&str, &str)] = &[
    ("lpm", "L/min"),
    ("LPM", "L/min"),
    ("psig", "psi"),
    ("Nm", "N·m"),
    ("kNm", "kN·m"),
    ("μs", "µs"),
    ("μm", "µm"),
    ("sec", "s"),
    ("inch", "in"),
];

/// Spellings refused with a reason: (spelling, hint).
const REFUSED: &[(&str, &str)] = &[
    ("psia", "pressures in a model are gauge (above the atmosphere): subtract 14.696 psi and write `psi`"),
    ("bara", "pressures in a model are gauge (above the atmosphere): subtract 1.01325 bar and write `bar`"),
    ("barg", "write `bar`: pressures in a model are gauge already"),
    ("gal", "US and imperial gallons differ: write the volume in `L`"),
    ("gpm", "US and imperial gallons differ: write the flow in `L/min`"),
    ("mn", "write `MN` (meganewton) or `mN` (millinewton)"),
];

/// Symbols never matched ignoring case: one letter, or a case that changes the prefix in a
/// way someone could mean (mN vs MN).
fn foldable(sym: &str) -> bool {
    sym.chars().count() > 1 && !REFUSED.iter().any(|(s, _)| s.eq_ignore_ascii_case(sym))
}

/// The unit of symbol `sym`: the table, an alias, or the one symbol it matches ignoring case.
fn lookup(sym: &str) -> Option<Unit> {
    let of = |&(_, scale, dim): &(&str, f64, [i32; 4])| Unit {
        scale,
        dim: Dim(dim),
    };
    if let Some(e) = SYMBOLS.iter().find(|(s, _, _)| *s == sym) {
        return Some(of(e));
    }
    if let Some((_, u)) = ALIASES.iter().find(|(s, _)| *s == sym) {
        return parse(u);
    }
    if !foldable(sym) {
        return None;
    }
    let mut folded = SYMBOLS
        .iter()
        .filter(|(s, _, _)| s.to_lowercase() == sym.to_lowercase());
    match (folded.next(), folded.next()) {
        (Some(e), None) => Some(of(e)),
        _ => None,
    }
}

struct Parser<'a> {
    s: &'a str,
    i: usize,
    /// The first symbol this table does not know.
    unknown: Option<&'a str>,
}

impl<'a> Parser<'a> {
    fn peek(&self) -> Option<char> {
        self.s[self.i..].chars().next()
    }
    fn bump(&mut self) -> Option<char> {
        let c = self.peek()?;
        self.i += c.len_utf8();
        Some(c)
    }
    fn skip_ws(&mut self) {
        while self.peek().is_some_and(char::is_whitespace) {
            self.bump();
        }
    }
    fn unit(&mut self) -> Option<Unit> {
        let mut u = self.factor()?;
        loop {
            self.skip_ws();
            let sign = match self.peek() {
                Some('·' | '*' | '⋅') => 1,
                Some('/') => -1,
                _ => return Some(u),
            };
            self.bump();
            let f = self.factor()?;
            u = Unit {
                scale: if sign > 0 {
                    u.scale * f.scale
                } else {
                    u.scale / f.scale
                },
                dim: u.dim.times(f.dim, sign),
            };
        }
    }
    fn factor(&mut self) -> Option<Unit> {
        self.skip_ws();
        let base = match self.peek()? {
            '√' => {
                self.bump();
                let f = self.factor()?;
                return Some(Unit {
                    scale: f.scale.sqrt(),
                    dim: f.dim.pow2(1, 2)?,
                });
            }
            '(' => {
                self.bump();
                let u = self.unit()?;
                self.skip_ws();
                (self.bump()? == ')').then_some(u)?
            }
            _ => {
                let start = self.i;
                while self.peek().is_some_and(|c| {
                    c.is_alphabetic() || c == '%' || c == '°' || c == '1' && self.i == start
                }) {
                    self.bump();
                }
                let sym: &'a str = &self.s[start..self.i];
                if sym.is_empty() {
                    return None;
                }
                let Some(u) = lookup(sym) else {
                    self.unknown.get_or_insert(sym);
                    return None;
                };
                u
            }
        };
        let n: i32 = match self.peek() {
            Some('²') => {
                self.bump();
                2
            }
            Some('³') => {
                self.bump();
                3
            }
            Some(c @ '2'..='9') => {
                self.bump();
                c.to_digit(10).and_then(|d| i32::try_from(d).ok())?
            }
            Some('⁻') => {
                self.bump();
                match self.bump()? {
                    '¹' => -1,
                    '²' => -2,
                    '³' => -3,
                    _ => return None,
                }
            }
            Some('^') => {
                self.bump();
                let start = self.i;
                if self.peek() == Some('-') {
                    self.bump();
                }
                while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                    self.bump();
                }
                self.s[start..self.i].parse().ok()?
            }
            _ => return Some(base),
        };
        Some(Unit {
            scale: base.scale.powi(n),
            dim: base.dim.pow2(n, 1)?,
        })
    }
}

/// Read `unit` to its end: the unit, or the first unknown symbol met (if that is why).
fn read(unit: &str) -> Result<Unit, Option<&str>> {
    let unit = unit.trim();
    if unit.is_empty() {
        return Ok(Unit {
            scale: 1.0,
            dim: Dim::NONE,
        });
    }
    let mut p = Parser {
        s: unit,
        i: 0,
        unknown: None,
    };
    let u = p.unit();
    p.skip_ws();
    match u {
        Some(u) if p.i == unit.len() => Ok(u),
        _ => Err(p.unknown),
    }
}

/// Read a unit: `"Pa"`, `"L/min"`, `"m³/(s·√Pa)"`, `"N·m·s/rad"`. `None` if it is not one
/// this table knows.
#[must_use]
pub fn parse(unit: &str) -> Option<Unit> {
    read(unit).ok()
}

/// Why `unit` is not a unit, as (message, hint): "unknown unit `Bar`" with a suggestion of
/// a known symbol that looks like it, or the reason a spelling is refused.
#[must_use]
pub fn why_not(unit: &str) -> (String, String) {
    let sym = match read(unit) {
        Ok(_) => return (format!("`{unit}` is a unit"), String::new()),
        Err(None) => {
            return (
                format!("cannot read the unit `{unit}`"),
                "units are symbols joined by `·`, `*` or `/`, with powers (`m²`, `m^2`, `m2`), e.g. `L/min`, `N·m/rad`".to_owned(),
            )
        }
        Err(Some(s)) => s,
    };
    let message = format!("unknown unit `{sym}`");
    if let Some((_, why)) = REFUSED.iter().find(|(s, _)| s.eq_ignore_ascii_case(sym)) {
        return (message, (*why).to_owned());
    }
    let names = SYMBOLS
        .iter()
        .map(|(s, _, _)| *s)
        .chain(ALIASES.iter().map(|(s, _)| *s));
    let lower = sym.to_lowercase();
    let near: Vec<&str> = names
        .filter(|s| {
            let l = s.to_lowercase();
            let sorted = |t: &str| {
                let mut c: Vec<char> = t.chars().collect();
                c.sort_unstable();
                c
            };
            l == lower
                || lower.chars().count() > 1
                    && (super::similar(&lower, &l) || sorted(&lower) == sorted(&l))
        })
        .take(3)
        .collect();
    let hint = if near.is_empty() {
        format!("known units: {}", known_list())
    } else {
        format!(
            "did you mean {}? (known units: {})",
            near.iter()
                .map(|s| format!("`{s}`"))
                .collect::<Vec<_>>()
                .join(" or "),
            known_list()
        )
    };
    (message, hint)
}

/// The symbols this table knows, for a hint.
fn known_list() -> String {
    SYMBOLS
        .iter()
        .skip(1)
        .map(|(s, _, _)| *s)
        .chain(ALIASES.iter().map(|(s, _)| *s))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Split `"200 bar"` into the expression `"200"` and the unit bar, if the text ends in a
/// space and a unit this table knows and the part before is not empty. Texts without a
/// unit give `None`.
#[must_use]
pub fn split_value(text: &str) -> Option<(&str, Unit)> {
    let (value, unit) = split_last(text)?;
    parse(unit).map(|u| (value, u))
}

/// Split `"200 Bar"` into `"200"` and `"Bar"` at the last space, whatever the last word is;
/// `None` without a space or with nothing before it.
#[must_use]
pub fn split_last(text: &str) -> Option<(&str, &str)> {
    let text = text.trim();
    let at = text.rfind(char::is_whitespace)?;
    let (value, unit) = (text[..at].trim_end(), text[at..].trim());
    (!value.is_empty()).then_some((value, unit))
}

/// Doubled exponents with their names, the declared units' kinds in words.
const NAMED: &[([i32; 4], &str)] = &[
    ([0, 0, 0, 0], "dimensionless"),
    ([0, 0, 0, A], "angle"),
    ([0, 2, 0, 0], "length"),
    ([0, 4, 0, 0], "area"),
    ([0, 6, 0, 0], "volume"),
    ([0, 6, 0, -A], "volume per radian"),
    ([0, 0, 2, 0], "time"),
    ([0, 0, -2, 0], "rate"),
    ([0, 0, -2, A], "angular speed"),
    ([2, 0, 0, 0], "mass"),
    ([2, 2, -4, 0], "force"),
    ([2, -2, -4, 0], "pressure"),
    ([0, 6, -2, 0], "volume flow"),
    ([0, 2, -2, 0], "velocity"),
    ([0, 2, -4, 0], "acceleration"),
    ([2, 4, -4, 0], "energy or torque"),
    ([2, 4, -6, 0], "power"),
    ([2, 0, -4, 0], "stiffness"),
    ([2, 0, -2, 0], "damping coefficient"),
    ([2, 4, -4, -A], "rotational stiffness"),
    ([2, 4, -2, -A], "rotational damping coefficient"),
    ([2, 4, 0, 0], "moment of inertia"),
    ([2, -6, 0, 0], "density"),
    ([2, -2, 0, 0], "mass per length"),
    ([2, -2, -2, 0], "viscosity"),
];

/// The common name of a dimension ("pressure", "volume per radian"), if it has one.
#[must_use]
pub fn name(dim: Dim) -> Option<&'static str> {
    NAMED.iter().find(|(d, _)| *d == dim.0).map(|(_, n)| *n)
}

/// The dimension in words ("pressure", "length", …) and SI symbols: "pressure (Pa)",
/// "stiffness (kg/s²)", or the symbols alone where it has no common name.
#[must_use]
pub fn describe(dim: Dim) -> String {
    let sym = symbols(dim);
    match name(dim) {
        Some(n) if sym == "1" => n.to_owned(),
        Some(n) => format!("{n} ({sym})"),
        None => format!("quantity in {sym}"),
    }
}

/// The dimension as SI symbols: "kg/s²", "m³/rad", "1" for none; never raw exponents.
#[must_use]
pub fn symbols(dim: Dim) -> String {
    const BASE: [&str; 4] = ["kg", "m", "s", "rad"];
    let power = |sym: &str, e2: i32| -> String {
        let e2 = e2.abs();
        match e2 {
            2 => sym.to_owned(),
            4 => format!("{sym}²"),
            6 => format!("{sym}³"),
            1 => format!("√{sym}"),
            e if e % 2 == 0 => format!("{sym}^{}", e / 2),
            e => format!("{sym}^({e}/2)"),
        }
    };
    // Pa for a pressure reads better than kg/(m·s²)
    let special: &[([i32; 4], &str)] = &[
        ([2, -2, -4, 0], "Pa"),
        ([2, 2, -4, 0], "N"),
        ([2, 4, -4, 0], "N·m"),
        ([2, 4, -6, 0], "W"),
        ([2, 0, -4, 0], "N/m"),
        ([2, 0, -2, 0], "N·s/m"),
        ([2, 4, -4, -A], "N·m/rad"),
        ([2, 4, -2, -A], "N·m·s/rad"),
        ([2, -2, -2, 0], "Pa·s"),
    ];
    if let Some((_, s)) = special.iter().find(|(d, _)| *d == dim.0) {
        return (*s).to_owned();
    }
    let num: Vec<String> = (0..4)
        .filter(|&i| dim.0[i] > 0)
        .map(|i| power(BASE[i], dim.0[i]))
        .collect();
    let den: Vec<String> = (0..4)
        .filter(|&i| dim.0[i] < 0)
        .map(|i| power(BASE[i], dim.0[i]))
        .collect();
    let num = if num.is_empty() {
        "1".to_owned()
    } else {
        num.join("·")
    };
    match den.len() {
        0 => num,
        1 => format!("{num}/{}", den[0]),
        _ => format!("{num}/({})", den.join("·")),
    }
}

/// A value for a parameter declared in `want` written as `"{value} {unit}"` whose unit `got`
/// differs from `want` only by an angle: the spelling that means what was probably meant
/// (`"250 cc/rev"` for a displacement per radian, `"1500 rev/min"` for an angular speed).
/// `None` if the units differ by more than an angle or not at all.
#[must_use]
pub fn angle_hint(value: &str, unit: &str, want: Unit, got: Unit) -> Option<String> {
    if want.dim == got.dim || want.dim.without_angle() != got.dim.without_angle() {
        return None;
    }
    let missing = want.dim.angle() - got.dim.angle();
    let with = |per: &str| -> String {
        match missing {
            -1 => format!("\"{value} {unit}/{per}\""),
            1 => match unit
                .strip_prefix("1/")
                .or_else(|| unit.strip_suffix("^-1"))
                .or_else(|| unit.strip_suffix("⁻¹"))
            {
                Some(per_time) => format!("\"{value} {per}/{per_time}\""),
                None => format!("\"{value} {per}·{unit}\""),
            },
            _ => String::new(),
        }
    };
    Some(if want.dim.angle() == 0 {
        "it takes no angle: write it without `rad`, `deg`, `rev`, `rpm` or `Hz`".to_owned()
    } else if missing.abs() == 1 {
        format!(
            "its unit counts an angle: write {} if it is per revolution, or {} if per radian",
            with("rev"),
            with("rad")
        )
    } else {
        "write the value with a unit of the declared kind".to_owned()
    })
}

/// A number for a message, exact but short: `1e-300` and `1e20` in exponent form, never
/// hundreds of digits; `0.25` and `2500000` as written.
#[must_use]
pub fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}
#[cfg(test)]
mod tests;
