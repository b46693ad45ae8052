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

/// The forward-mode gradient of every function and operator against central
/// differences, and no string work left in a compiled expression.
#[test]
fn exact_gradients_match_central_differences() {
    let names: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
    let exprs = [
        "a*b + c/a - b^2",
        "sqrt(a)*exp(-b) + ln(c)*log10(a)",
        "sin(a)*cos(b) + tan(c/4) + asin(b/3) + acos(c/4) + atan(a)",
        "atan2(a, b) + sinh(b) - cosh(c/3) + tanh(a)",
        "abs(b - 2) + pow(a, c) + a^b + deg(a) + rad(b)",
        "min(a, b, c) + max(a*2, b) + clamp(a, 0, 1) + clamp(c, 0, 2)",
        "-a*sign(b) + step(c) + 2^a",
    ];
    let u = [0.7, 1.3, 2.6];
    for src in exprs {
        let c = Expr::parse(src)
            .unwrap()
            .compile(&|_| None, &names)
            .unwrap();
        let mut g = [0.0; 3];
        let v = c.eval_grad(&u, &mut g);
        assert!((v - c.eval(&u)).abs() < 1e-14 * v.abs().max(1.0), "{src}");
        for k in 0..3 {
            let h = 1e-6;
            let (mut p, mut m) = (u, u);
            p[k] += h;
            m[k] -= h;
            let fd = (c.eval(&p) - c.eval(&m)) / (2.0 * h);
            assert!(
                (fd - g[k]).abs() < 1e-7 * fd.abs().max(1.0),
                "{src}: ∂{k} {} vs {fd}",
                g[k]
            );
        }
    }
}
