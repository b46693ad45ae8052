use super::*;
use bondgraph::check_partials;
use PortCausality::{EffortOut, FlowOut};

/// 40 cm³/rev.
const D: f64 = 40e-6 / (2.0 * std::f64::consts::PI);

fn lossy(role: Role) -> Machine {
    Machine::new(role, D)
        .unwrap()
        .with_leakage(2e-12)
        .unwrap()
        .with_friction(FrictionLaw::coulomb_viscous(3.0, 0.5, 2e-3).unwrap())
}

/// (power in, Q, T) at ε, P_a, P_b, ω, from the law (the element's `eval` calls the same
/// functions; `partials_match_central_differences` runs `eval` itself).
fn power_in(m: &Machine, eps: f64, p_a: f64, p_b: f64, omega: f64) -> (f64, f64, f64) {
    let d = eps * D;
    let q = m.flow(d, omega, p_a - p_b);
    let t = m.torque(d, omega, p_a - p_b);
    let f_in_shaft = m.r() * omega;
    (p_a * q - p_b * q + t * f_in_shaft, q, t)
}

/// A deterministic spread of states over all four quadrants.
fn states() -> Vec<(f64, f64, f64, f64)> {
    let mut v = Vec::new();
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    for _ in 0..500 {
        // ε, P_a, P_b (Pa), ω (rad/s)
        v.push((next(), 3e7 * next(), 3e7 * next(), 300.0 * next()));
    }
    v
}

#[test]
fn lossless_machine_conserves_power() {
    for role in [Role::Pump, Role::Motor] {
        let m = Machine::new(role, D).unwrap();
        for (eps, p_a, p_b, w) in states() {
            let (p, q, t) = power_in(&m, eps, p_a, p_b, w);
            let scale = (p_a.abs() + p_b.abs()) * q.abs() + (t * w).abs();
            assert!(p.abs() <= 1e-14 * scale, "{role:?}: {p:e} of {scale:e}");
        }
    }
}

#[test]
fn losses_dissipate_in_all_four_quadrants() {
    for role in [Role::Pump, Role::Motor] {
        let m = lossy(role);
        let mut quadrants = [false; 4];
        for (eps, p_a, p_b, w) in states() {
            let (p, _, _) = power_in(&m, eps, p_a, p_b, w);
            let delta = p_a - p_b;
            let dissipation = 2e-12 * delta * delta + m.friction.force(w) * w;
            assert!(dissipation >= 0.0);
            assert!(
                (p - dissipation).abs()
                    <= 1e-12 * (p_a.abs() + p_b.abs()) * D * w.abs() + 1e-12 * dissipation,
                "{role:?}: {p:e} vs {dissipation:e}"
            );
            quadrants[usize::from(w * eps > 0.0) * 2 + usize::from(delta > 0.0)] = true;
        }
        assert_eq!(quadrants, [true; 4]);
    }
}

#[test]
fn efficiencies_match_the_hand_formulas() {
    // Pump at 150 rad/s against 20 MPa: η_v = 1 − C_l·Δp/(D·ω), η_hm = DΔp/(DΔp + T_f).
    let (w, dp) = (150.0, 20e6);
    let pump = lossy(Role::Pump);
    let (_, q, t) = power_in(&pump, 1.0, 0.0, dp, w);
    let t_f = 3.0 * (w / 0.5).tanh() + 2e-3 * w;
    let eta_v = 1.0 - 2e-12 * dp / (D * w);
    let eta_hm = D * dp / (D * dp + t_f);
    assert!((q / (D * w) - eta_v).abs() < 1e-14, "{}", q / (D * w));
    assert!((D * dp / t - eta_hm).abs() < 1e-14);
    assert!((q * dp / (t * w) - eta_v * eta_hm).abs() < 1e-14);
    // hand numbers: D = 6.366e-6 m³/rad, Q_ideal = 9.549e-4 m³/s, leak 4e-5 m³/s,
    // T_ideal = 127.3 N·m, T_f = 3.3 N·m
    assert!((eta_v - 0.958_112).abs() < 1e-6, "{eta_v}");
    assert!((eta_hm - 0.974_737).abs() < 1e-6, "{eta_hm}");
    // Motor fed at 20 MPa turning at 150 rad/s: η_v = Dω/(Dω + C_l·Δp), η_hm = 1 − T_f/(DΔp).
    let motor = lossy(Role::Motor);
    let (_, q, t) = power_in(&motor, 1.0, dp, 0.0, w);
    let eta_v = D * w / (D * w + 2e-12 * dp);
    let eta_hm = 1.0 - t_f / (D * dp);
    assert!((D * w / q - eta_v).abs() < 1e-14);
    assert!((t / (D * dp) - eta_hm).abs() < 1e-14);
    assert!((t * w / (q * dp) - eta_v * eta_hm).abs() < 1e-14);
}

#[test]
fn motor_is_a_pump_with_its_ports_swapped() {
    let (pump, motor) = (lossy(Role::Pump), lossy(Role::Motor));
    for (eps, p_a, p_b, w) in states().into_iter().take(50) {
        let d = eps * D;
        // motor (a, b, ω) = pump (b, a, −ω): flow reversed, torque equal
        let qm = motor.flow(d, w, p_a - p_b);
        let qp = pump.flow(d, -w, p_b - p_a);
        assert!((qm + qp).abs() <= 1e-15 * qm.abs().max(1e-9));
        let tm = motor.torque(d, w, p_a - p_b);
        let tp = pump.torque(d, -w, p_b - p_a);
        assert!((tm - tp).abs() <= 1e-12 * tm.abs().max(1.0));
    }
}

#[test]
fn partials_match_central_differences() {
    for role in [Role::Pump, Role::Motor] {
        let m = lossy(role).with_fraction(fraction()).unwrap();
        for sign in [1.0, -1.0] {
            let ports = [(1, 1.0, FlowOut), (1, -1.0, FlowOut), (1, sign, EffortOut)];
            // P_a, Q_a, P_b, Q_b, T, ω_in, eps
            for (pa, pb, w) in [(1e5, 2e7, 120.0), (2.5e7, 3e5, -40.0), (1e6, 1.1e6, 0.2)] {
                let point = [pa, 1e-4, pb, 1e-4, 10.0, w, 0.3];
                assert_eq!(check_partials(&m, &ports, &point), Ok(2), "{role:?}");
            }
        }
    }
    // driven at a modulated speed: inputs eps, speed
    let speed = Param::modulated(vec!["w".into()], |_, u| 100.0 * u[0]);
    let m = Machine::pump_at_speed(D, speed)
        .unwrap()
        .with_fraction(fraction())
        .unwrap()
        .with_leakage(2e-12)
        .unwrap()
        .with_friction(FrictionLaw::coulomb_viscous(3.0, 0.5, 2e-3).unwrap());
    let ports = [(1, 1.0, FlowOut), (1, -1.0, FlowOut)];
    // P_a, Q_a, P_b, Q_b, eps, w
    let point = [1e5, 1e-4, 2e7, 1e-4, -0.2, 1.3];
    assert_eq!(check_partials(&m, &ports, &point), Ok(2));
}

/// ε = 0.5 + 0.4·u, a variable machine's setting from a signal u.
fn fraction() -> Param {
    Param::modulated(vec!["eps".into()], |_, u| 0.5 + 0.4 * u[0])
}

#[test]
fn pump_at_speed_is_a_flow_source_with_leakage() {
    let m = Machine::pump_at_speed(D, 150.0)
        .unwrap()
        .with_leakage(2e-12)
        .unwrap();
    assert_eq!(
        m.ports(),
        Ports::Fixed(vec![PortSpec::new("a", 1), PortSpec::new("b", 1)])
    );
    // Q = D·ω − C_l·(P_b − P_a)
    let q = m.flow(D, 150.0, 0.0 - 20e6);
    assert!((q - (D * 150.0 - 2e-12 * 20e6)).abs() < 1e-18);
    assert_eq!(m.signal_outputs(), vec![SignalSpec::scalar("torque")]);
}

#[test]
fn clamps_and_rejects() {
    assert!(Machine::new(Role::Pump, 0.0).is_err());
    assert!(Machine::new(Role::Motor, f64::NAN).is_err());
    assert!(Machine::new(Role::Pump, D)
        .unwrap()
        .with_fraction(1.5)
        .is_err());
    assert!(Machine::new(Role::Pump, D)
        .unwrap()
        .with_leakage(-1.0)
        .is_err());
    assert!(Machine::pump_at_speed(D, f64::INFINITY).is_err());
    assert_eq!(
        Machine::new(Role::Motor, D).unwrap().kind(),
        "hydraulics.motor"
    );
    // a modulated fraction beyond ±1 is clamped: ∂/∂ε = 0 there
    let m = Machine::new(Role::Pump, D)
        .unwrap()
        .with_fraction(Param::modulated(vec!["eps".into()], |_, u| u[0]))
        .unwrap();
    let ports = [(1, 1.0, FlowOut), (1, -1.0, FlowOut), (1, 1.0, EffortOut)];
    let point = [1e5, 1e-4, 2e7, 1e-4, 10.0, 100.0, 1.7];
    assert_eq!(check_partials(&m, &ports, &point), Ok(2));
}
