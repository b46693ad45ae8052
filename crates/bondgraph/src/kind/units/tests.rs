//! The unit table and its messages.
use super::*;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs()
}

#[test]
fn declared_units_parse_to_si_dimensions() {
    let pa = parse("Pa").unwrap();
    assert_eq!(pa.dim, Dim([2, -2, -4, 0]));
    let q = parse("m³/s").unwrap();
    assert_eq!(q.dim, Dim([0, 6, -2, 0]));
    let alpha = parse("m³/(s·√Pa)").unwrap();
    assert_eq!(alpha.dim, Dim([-1, 7, 0, 0]));
    assert_eq!(parse("N·s/m").unwrap().dim, Dim([2, 0, -2, 0]));
    assert_eq!(parse("Pa·s/m³").unwrap().dim, Dim([2, -8, -2, 0]));
    assert_eq!(parse("1").unwrap().dim, Dim([0, 0, 0, 0]));
    assert_eq!(parse("m^-1").unwrap().dim, Dim([0, -2, 0, 0]));
    assert_eq!(parse("m³/rad").unwrap().dim, Dim([0, 6, 0, -2]));
    assert_eq!(parse("N·m·s/rad").unwrap().dim, Dim([2, 4, -2, -2]));
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
    assert_eq!(describe(parse("kN").unwrap().dim), "force (N)");
}

/// Every pair of units that differ only by a dimensionless factor that matters (issue
/// 37, items 1 and 8): the decision for each.
#[test]
fn units_that_differ_by_an_angle_are_told_apart() {
    let per_rad = parse("m³/rad").unwrap();
    let rad_s = parse("rad/s").unwrap();
    // cc is a volume, cc/rev a volume per angle: not the same kind
    assert_ne!(parse("cc").unwrap().dim, per_rad.dim);
    let cc_rev = parse("cc/rev").unwrap();
    assert_eq!(cc_rev.dim, per_rad.dim);
    assert!(close(cc_rev.scale, 1e-6 / TAU));
    // rad, deg, rev: one kind, the right factors
    assert!(close(parse("rev").unwrap().scale, TAU));
    assert!(close(parse("deg").unwrap().scale, TAU / 360.0));
    assert_eq!(parse("rev").unwrap().dim, parse("rad").unwrap().dim);
    // rpm, rev/min, Hz, rev/s are angular speeds; 1/min, min^-1 and 1/s are not
    for (u, si) in [
        ("rpm", TAU / 60.0),
        ("RPM", TAU / 60.0),
        ("rev/min", TAU / 60.0),
        ("Hz", TAU),
        ("rev/s", TAU),
        ("deg/s", TAU / 360.0),
    ] {
        let p = parse(u).unwrap();
        assert_eq!(p.dim, rad_s.dim, "{u}");
        assert!(close(p.scale, si), "{u}");
    }
    for u in ["1/min", "min^-1", "min⁻¹", "1/s"] {
        let p = parse(u).unwrap();
        assert_ne!(p.dim, rad_s.dim, "{u}");
        assert_eq!(p.dim.without_angle(), rad_s.dim.without_angle(), "{u}");
    }
    // % and 1 are the same kind, a factor 0.01 apart
    assert_eq!(parse("%").unwrap().dim, parse("1").unwrap().dim);
    assert!(close(parse("%").unwrap().scale, 0.01));
    // and angles are not dimensionless numbers
    assert_ne!(parse("deg").unwrap().dim, parse("1").unwrap().dim);
}

#[test]
fn angle_hints_write_the_unit_that_was_meant() {
    let h = |v: &str, u: &str, want: &str| {
        angle_hint(v, u, parse(want).unwrap(), parse(u).unwrap()).unwrap_or_default()
    };
    assert!(h("250", "cc", "m³/rad").contains("\"250 cc/rev\""));
    assert!(h("250", "cc", "m³/rad").contains("\"250 cc/rad\""));
    assert!(h("1500", "1/min", "rad/s").contains("\"1500 rev/min\""));
    assert!(h("1500", "min^-1", "rad/s").contains("\"1500 rev/min\""));
    assert!(h("30", "deg", "1").contains("no angle"));
    assert!(angle_hint("3", "m", parse("Pa").unwrap(), parse("m").unwrap()).is_none());
}

#[test]
fn common_spellings_are_read_or_named() {
    for (u, si) in [
        ("Bar", 1e5),
        ("BAR", 1e5),
        ("ml", 1e-6),
        ("mm2", 1e-6),
        ("cm3", 1e-6),
        ("m3/h", 1.0 / 3600.0),
        ("lpm", 1e-3 / 60.0),
        ("µs", 1e-6),
        ("μs", 1e-6),
        ("atm", 101_325.0),
        ("psig", 6_894.757_293_168),
        ("in^2", 0.0254 * 0.0254),
        ("KPA", 1e3),
        ("Nm", 1.0),
    ] {
        let p = parse(u).unwrap_or_else(|| panic!("{u}"));
        assert!(close(p.scale, si), "{u}: {}", p.scale);
    }
    // case matters where a prefix could be meant either way, and one letter is never folded
    assert!(parse("mn").is_none());
    assert!(close(parse("mbar").unwrap().scale, 1e2));
    assert!(parse("T").is_none());
    let (m, h) = why_not("barr");
    assert_eq!(m, "unknown unit `barr`");
    assert!(h.contains("`bar`"), "{h}");
    let (m, h) = why_not("N/mmx");
    assert_eq!(m, "unknown unit `mmx`", "{h}");
    let (_, h) = why_not("psia");
    assert!(h.contains("gauge"), "{h}");
    let (_, h) = why_not("gal");
    assert!(h.contains("gallons"), "{h}");
}

#[test]
fn dimensions_are_named_in_words_and_symbols_never_exponents() {
    assert_eq!(describe(parse("N/m").unwrap().dim), "stiffness (N/m)");
    assert_eq!(
        describe(parse("m³/rad").unwrap().dim),
        "volume per radian (m³/rad)"
    );
    assert_eq!(describe(parse("1").unwrap().dim), "dimensionless");
    assert_eq!(symbols(parse("m³/(s·√Pa)").unwrap().dim), "m^(7/2)/√kg");
    assert_eq!(symbols(parse("kg/(m·s)").unwrap().dim), "Pa·s");
    assert_eq!(symbols(parse("m/s³").unwrap().dim), "m/s³");
    assert_eq!(symbols(parse("1/(s·rad)").unwrap().dim), "1/(s·rad)");
    assert!(!describe(parse("m^5/s").unwrap().dim).contains("^1"));
}

#[test]
fn numbers_in_messages_are_short() {
    assert_eq!(short(1e-300), "1e-300");
    assert_eq!(short(1e20), "1e20");
    assert_eq!(short(0.25), "0.25");
    assert_eq!(short(2.5e7), "25000000");
    assert_eq!(short(-3.0), "-3");
}
