//! Units: a declared unit (`"Pa"`, `"m³/s"`, `"m³/(s·√Pa)"`) and a value written with one
//! (`"200 bar"`, `"40 L/min"`, `"30 deg"`) are read into a scale to SI and a dimension over
//! mass, length and time, so that the loader converts `"200 bar"` to 2e7 Pa and refuses
//! `"3 m"` for a pressure.
//!
//! Grammar: `unit := factor (('·' | '*' | '/') factor)*`, `factor := ('√' factor | '(' unit
//! ')' | symbol) power?`, `power := '²' | '³' | '⁻¹' | '^' integer`; `/` applies to the factor
//! right after it. Angles (rad, deg, rev) are dimensionless.

/// Exponents of mass, length and time, doubled (so √Pa is representable).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dim(pub [i32; 3]);

impl Dim {
    const NONE: Self = Self([0, 0, 0]);
    fn times(self, o: Self, sign: i32) -> Self {
        Self([
            self.0[0] + sign * o.0[0],
            self.0[1] + sign * o.0[1],
            self.0[2] + sign * o.0[2],
        ])
    }
    fn pow2(self, num: i32, den: i32) -> Option<Self> {
        let f = |e: i32| (e * num % den == 0).then_some(e * num / den);
        Some(Self([f(self.0[0])?, f(self.0[1])?, f(self.0[2])?]))
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

const SYMBOLS: &[(&str, f64, [i32; 3])] = &[
    ("1", 1.0, [0, 0, 0]),
    ("%", 0.01, [0, 0, 0]),
    ("rad", 1.0, [0, 0, 0]),
    ("deg", std::f64::consts::PI / 180.0, [0, 0, 0]),
    ("°", std::f64::consts::PI / 180.0, [0, 0, 0]),
    ("rev", std::f64::consts::TAU, [0, 0, 0]),
    ("m", 1.0, [0, 2, 0]),
    ("km", 1e3, [0, 2, 0]),
    ("cm", 1e-2, [0, 2, 0]),
    ("mm", 1e-3, [0, 2, 0]),
    ("µm", 1e-6, [0, 2, 0]),
    ("um", 1e-6, [0, 2, 0]),
    ("s", 1.0, [0, 0, 2]),
    ("ms", 1e-3, [0, 0, 2]),
    ("min", 60.0, [0, 0, 2]),
    ("h", 3600.0, [0, 0, 2]),
    ("Hz", 1.0, [0, 0, -2]),
    ("rpm", std::f64::consts::TAU / 60.0, [0, 0, -2]),
    ("kg", 1.0, [2, 0, 0]),
    ("g", 1e-3, [2, 0, 0]),
    ("t", 1e3, [2, 0, 0]),
    ("N", 1.0, [2, 2, -4]),
    ("kN", 1e3, [2, 2, -4]),
    ("MN", 1e6, [2, 2, -4]),
    ("Pa", 1.0, [2, -2, -4]),
    ("kPa", 1e3, [2, -2, -4]),
    ("MPa", 1e6, [2, -2, -4]),
    ("GPa", 1e9, [2, -2, -4]),
    ("bar", 1e5, [2, -2, -4]),
    ("mbar", 1e2, [2, -2, -4]),
    ("psi", 6_894.757_293_168, [2, -2, -4]),
    ("J", 1.0, [2, 4, -4]),
    ("kJ", 1e3, [2, 4, -4]),
    ("W", 1.0, [2, 4, -6]),
    ("kW", 1e3, [2, 4, -6]),
    ("L", 1e-3, [0, 6, 0]),
    ("l", 1e-3, [0, 6, 0]),
    ("mL", 1e-6, [0, 6, 0]),
    ("cc", 1e-6, [0, 6, 0]),
];

struct Parser<'a> {
    s: &'a str,
    i: usize,
}

impl Parser<'_> {
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
                let sym = &self.s[start..self.i];
                let &(_, scale, dim) = SYMBOLS.iter().find(|(s, _, _)| *s == sym)?;
                Unit {
                    scale,
                    dim: Dim(dim),
                }
            }
        };
        let (num, den) = match self.peek() {
            Some('²') => (2, 1),
            Some('³') => (3, 1),
            Some('⁻') => {
                self.bump();
                match self.peek()? {
                    '¹' => (-1, 1),
                    '²' => (-2, 1),
                    '³' => (-3, 1),
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
                (self.s[start..self.i].parse().ok()?, 0)
            }
            _ => return Some(base),
        };
        if den == 1 {
            self.bump();
        }
        let n: i32 = num;
        Some(Unit {
            scale: base.scale.powi(n),
            dim: base.dim.pow2(n, 1)?,
        })
    }
}

/// Read a unit: `"Pa"`, `"L/min"`, `"m³/(s·√Pa)"`, `"N·m·s/rad"`. `None` if it is not one
/// this table knows.
#[must_use]
pub fn parse(unit: &str) -> Option<Unit> {
    let unit = unit.trim();
    if unit.is_empty() {
        return Some(Unit {
            scale: 1.0,
            dim: Dim::NONE,
        });
    }
    let mut p = Parser { s: unit, i: 0 };
    let u = p.unit()?;
    p.skip_ws();
    (p.i == unit.len()).then_some(u)
}

/// Split `"200 bar"` into the expression `"200"` and the unit bar, if the text ends in a
/// space and a unit this table knows and the part before is not empty. Texts without a
/// unit give `None`.
#[must_use]
pub fn split_value(text: &str) -> Option<(&str, Unit)> {
    let text = text.trim();
    let at = text.rfind(char::is_whitespace)?;
    let (value, unit) = (text[..at].trim_end(), text[at..].trim());
    if value.is_empty() {
        return None;
    }
    parse(unit).map(|u| (value, u))
}

/// The dimension as words a user recognises ("pressure", "length", …), else the SI form.
#[must_use]
pub fn describe(dim: Dim) -> String {
    const NAMED: &[([i32; 3], &str)] = &[
        ([0, 0, 0], "dimensionless"),
        ([0, 2, 0], "length"),
        ([0, 4, 0], "area"),
        ([0, 6, 0], "volume"),
        ([0, 0, 2], "time"),
        ([0, 0, -2], "rate (1/s)"),
        ([2, 0, 0], "mass"),
        ([2, 2, -4], "force"),
        ([2, -2, -4], "pressure"),
        ([0, 6, -2], "volume flow"),
        ([0, 2, -2], "velocity"),
        ([2, 4, -4], "energy or torque"),
        ([2, 4, -6], "power"),
    ];
    NAMED.iter().find(|(d, _)| *d == dim.0).map_or_else(
        || {
            format!(
                "kg^{} m^{} s^{}",
                f64::from(dim.0[0]) / 2.0,
                f64::from(dim.0[1]) / 2.0,
                f64::from(dim.0[2]) / 2.0
            )
        },
        |(_, n)| (*n).to_owned(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs()
    }

    #[test]
    fn declared_units_parse_to_si_dimensions() {
        let pa = parse("Pa").unwrap();
        assert_eq!(pa.dim, Dim([2, -2, -4]));
        let q = parse("m³/s").unwrap();
        assert_eq!(q.dim, Dim([0, 6, -2]));
        let alpha = parse("m³/(s·√Pa)").unwrap();
        assert_eq!(alpha.dim, Dim([-1, 7, 0]));
        assert_eq!(parse("N·s/m").unwrap().dim, Dim([2, 0, -2]));
        assert_eq!(parse("Pa·s/m³").unwrap().dim, Dim([2, -8, -2]));
        assert_eq!(parse("1").unwrap().dim, Dim([0, 0, 0]));
        assert_eq!(parse("m^-1").unwrap().dim, Dim([0, -2, 0]));
        assert!(parse("furlong").is_none());
        assert!(parse("m³/(s").is_none());
    }

    #[test]
    fn values_with_units_convert_to_si() {
        let (v, u) = split_value("200 bar").unwrap();
        assert_eq!(v, "200");
        assert!(close(u.scale, 1e5));
        let (_, u) = split_value("40 L/min").unwrap();
        assert!(close(u.scale, 1e-3 / 60.0));
        assert_eq!(u.dim, parse("m³/s").unwrap().dim);
        let (_, u) = split_value("30 deg").unwrap();
        assert!(close(u.scale, std::f64::consts::PI / 180.0));
        let (v, u) = split_value("pi/4*d^2 mm²").unwrap();
        assert_eq!(v, "pi/4*d^2");
        assert!(close(u.scale, 1e-6));
        assert!(split_value("2 * k").is_none());
        assert!(split_value("bar").is_none());
        assert_eq!(describe(parse("kN").unwrap().dim), "force");
    }
}
