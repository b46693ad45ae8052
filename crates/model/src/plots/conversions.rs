//! The named unit conversions of a `[[plot]]` series or panel (`convert = "rad->deg"`).

/// The named unit conversions: (name, scale, offset, unit shown); shown = scale · value +
/// offset.
pub const CONVERSIONS: &[(&str, f64, f64, &str)] = &[
    ("rad->deg", 180.0 / std::f64::consts::PI, 0.0, "deg"),
    ("deg->rad", std::f64::consts::PI / 180.0, 0.0, "rad"),
    ("rad/s->rpm", 30.0 / std::f64::consts::PI, 0.0, "rpm"),
    ("rad/s->deg/s", 180.0 / std::f64::consts::PI, 0.0, "deg/s"),
    ("Pa->kPa", 1e-3, 0.0, "kPa"),
    ("Pa->bar", 1e-5, 0.0, "bar"),
    ("Pa->MPa", 1e-6, 0.0, "MPa"),
    ("m^3/s->L/s", 1e3, 0.0, "L/s"),
    ("m^3/s->L/min", 6e4, 0.0, "L/min"),
    ("m^3->L", 1e3, 0.0, "L"),
    ("m->mm", 1e3, 0.0, "mm"),
    ("m->cm", 1e2, 0.0, "cm"),
    ("m/s->mm/s", 1e3, 0.0, "mm/s"),
    ("N->kN", 1e-3, 0.0, "kN"),
    ("N*m->kN*m", 1e-3, 0.0, "kN·m"),
    ("W->kW", 1e-3, 0.0, "kW"),
    ("J->kJ", 1e-3, 0.0, "kJ"),
    ("A->mA", 1e3, 0.0, "mA"),
    ("V->mV", 1e3, 0.0, "mV"),
    ("K->degC", 1.0, -273.15, "°C"),
    ("1->%", 100.0, 0.0, "%"),
];

/// The named conversion `name`: (scale, offset, unit shown).
#[must_use]
pub fn conversion(name: &str) -> Option<(f64, f64, &'static str)> {
    CONVERSIONS
        .iter()
        .find(|c| c.0 == name)
        .map(|c| (c.1, c.2, c.3))
}
