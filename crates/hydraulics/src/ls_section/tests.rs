use super::*;
use bondgraph::check_partials;

const Q_NOM: f64 = 40e-3 / 60.0; // 40 L/min

fn section(c: Compensator) -> LsSection {
    let dp_comp = match c {
        Compensator::Pre => 10e5,
        Compensator::Post => 1e5,
    };
    LsSection::new(
        c,
        Q_NOM,
        10e5,
        Param::modulated(vec!["x".into()], |_, u| u[0]),
        dp_comp,
        0.05,
        1e5,
    )
    .unwrap()
}

#[test]
fn pre_compensated_flow_is_load_independent() {
    let s = section(Compensator::Pre).with_leakage(0.0).unwrap();
    // the pump 20 bar over the load, loads from 10 % to 90 % of 250 bar: Q = q_nom·x
    for x in [0.25, 0.5, 1.0] {
        for load in [25e5, 100e5, 225e5] {
            let q = s.flows(x, &[load + 20e5, 0.0, load, 5e5, load, 0.0]);
            assert!(((-q[A]) / (Q_NOM * x) - 1.0).abs() < 1e-12, "{x} {load}");
        }
    }
    // the pump below the compensator's drop: the bare spool, α·x·regRoot(Δp)
    let q = s.flows(0.5, &[105e5, 0.0, 100e5, 0.0, 100e5, 0.0])[P];
    let e = Q_NOM / reg_root(10e5, 1e5) * 0.5 * reg_root(5e5, 1e5);
    assert!((q - e).abs() < 1e-15, "{q} {e}");
    // reverse: the compensator closes (load-holding check)
    assert_eq!(s.flows(0.5, &[80e5, 0.0, 100e5, 0.0, 100e5, 0.0])[P], 0.0);
}

#[test]
fn post_compensated_sections_share_one_spool_drop() {
    let s = section(Compensator::Post).with_leakage(0.0).unwrap();
    // two sections on one pump and one LS gallery (the heavier load, 150 bar, less the
    // bleed's drop): whatever the pump pressure, the flows are in the ratio of the openings
    let p_ls = 150e5 - 0.3e5;
    for p_p in [152e5, 155e5, 170e5] {
        let q1 = -s.flows(1.0, &[p_p, 0.0, 50e5, 0.0, 50e5, p_ls])[A];
        let q2 = -s.flows(0.5, &[p_p, 0.0, 150e5, 0.0, 150e5, p_ls])[A];
        assert!((q1 / q2 - 2.0).abs() < 2e-3, "{p_p}: {}", q1 / q2);
        // and that is the spool at P_P − P_LS − Δp_s
        let e = Q_NOM / reg_root(10e5, 1e5) * reg_root(p_p - p_ls - 1e5, 1e5);
        // (within the smooth max's δ²/(4·|P_X + Δp_s − P_A|), 1 Pa here)
        assert!((q1 / e - 1.0).abs() < 2e-5, "{q1} {e}");
    }
}

#[test]
fn ls_port_senses_the_open_port_and_drains_at_centre() {
    let s = section(Compensator::Pre);
    let p = [200e5, 1e5, 120e5, 60e5, 90e5, 0.0];
    let k = 5e-7;
    let q = s.flows(0.0, &p)[LS];
    assert!((q - k * reg_root(89e5, 1e5)).abs() < 1e-15);
    let q = s.flows(0.3, &p)[LS];
    assert!((q + k * reg_root(30e5, 1e5)).abs() < 1e-15);
    let q = s.flows(-0.3, &p)[LS];
    assert!((q - k * reg_root(30e5, 1e5)).abs() < 1e-15);
    // half-way: both edges half open
    let q = s.flows(0.025, &p)[LS];
    let e = 0.5 * k * (reg_root(89e5, 1e5) - reg_root(30e5, 1e5));
    assert!((q - e).abs() < 1e-15);
}

#[test]
fn conserves_volume_and_dissipates() {
    let mut st: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        st ^= st << 13;
        st ^= st >> 7;
        st ^= st << 17;
        (st >> 11) as f64 / (1u64 << 53) as f64
    };
    for c in [Compensator::Pre, Compensator::Post] {
        let s = section(c);
        for _ in 0..3000 {
            let x = 2.4 * next() - 1.2;
            let p = [0.0; 6].map(|_| 30e6 * next() - 1e6);
            let q = s.flows(x, &p);
            assert_eq!(q[X], 0.0);
            let through: f64 = q.iter().map(|v| v.abs()).sum();
            assert!(q.iter().sum::<f64>().abs() <= 1e-14 * through);
            let power: f64 = (0..6).map(|k| p[k] * q[k]).sum();
            let scale: f64 = (0..6).map(|k| (p[k] * q[k]).abs()).sum();
            assert!(power >= -1e-12 * scale, "{c:?} {x} {p:?}: {power:e}");
        }
    }
}

#[test]
fn partials_match_central_differences() {
    let ports = [(1, 1.0, PortCausality::FlowOut); 6];
    for c in [Compensator::Pre, Compensator::Post] {
        let s = section(c);
        let n = s.n_ports();
        for x in [-0.7, -0.02, 0.03, 0.4] {
            for p in [
                [170e5, 1e5, 100e5, 20e5, 99.6e5, 99.5e5],
                [108e5, 1e5, 100e5, 20e5, 99.7e5, 99.7e5],
                [120e5, 1e5, 30e5, 100e5, 99.4e5, 99.4e5],
                [102e5, 1e5, 100e5, 100e5, 100.5e5, 98.5e5],
            ] {
                let mut point = Vec::new();
                for pk in &p[..n] {
                    point.extend([*pk, 1e-5]);
                }
                point.push(x);
                assert_eq!(
                    check_partials(&s, &ports[..n], &point),
                    Ok(1),
                    "{c:?} {x} {p:?}"
                );
            }
        }
    }
}

#[test]
fn spool_lag_is_a_first_order_state_with_exact_partials() {
    let s = section(Compensator::Post)
        .with_spool_lag(Some(0.05))
        .unwrap();
    assert_eq!(s.states(), vec![StateSpec::new("x", 0.0).nominal(1.0)]);
    let ports = [(1, 1.0, PortCausality::FlowOut); 6];
    // per port (P, Q), then the command x_v, then the state x
    for (u, x) in [(0.6, 0.3), (1.4, -0.2), (-0.5, -0.45)] {
        let mut point = Vec::new();
        for pk in [170e5, 1e5, 100e5, 20e5, 99.6e5, 99.5e5] {
            point.extend([pk, 1e-5]);
        }
        point.extend([u, x]);
        assert_eq!(check_partials(&s, &ports, &point), Ok(2), "{u} {x}");
    }
    assert!(section(Compensator::Pre).with_spool_lag(Some(0.0)).is_err());
}

#[test]
fn rejects_bad_parameters() {
    let s = |q: f64, dp: f64, sm: f64| LsSection::new(Compensator::Pre, q, 10e5, 0.0, dp, sm, 1e5);
    assert!(s(0.0, 1e6, 0.05).is_err());
    assert!(s(1e-3, 0.0, 0.05).is_err());
    assert!(s(1e-3, 1e6, 0.7).is_err());
    assert!(s(1e-3, 1e6, 0.05)
        .unwrap()
        .with_ls_edges(0.0, 0.05)
        .is_err());
    assert!(s(1e-3, 1e6, 0.05)
        .unwrap()
        .with_ls_edges(1e-7, 0.0)
        .is_err());
    assert!(s(1e-3, 1e6, 0.05).unwrap().with_leakage(-1.0).is_err());
}
