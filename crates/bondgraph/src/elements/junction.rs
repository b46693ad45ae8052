//! Junctions: `0` (common effort, Σ f_in = 0) and `1` (common flow, Σ s·e = 0).
//!
//! A junction takes any number of bonds of one dimension. Its *dominant* bond is the one that
//! decides the common variable: at a 0-junction the bond that brings the effort (the junction
//! computes its flow), at a 1-junction the bond that brings the flow (the junction computes
//! its effort). Each junction works in two stages, so that distributing the common variable
//! and summing the others never form a false algebraic loop. Power is conserved exactly.

use crate::bond::PortCausality;
use crate::element::{CausalRule, Element, Io, Layout, Ports, Slot, Stage};
use crate::kind::KindDecl;
use crate::local_jacobian::LocalJacobian;

fn dominant(io: &Io<'_>, c: PortCausality) -> usize {
    io.layout
        .ports
        .iter()
        .position(|p| p.causality == c)
        .unwrap_or(0)
}

/// Call `$f::<N>(args)` if `dim` is N = 2..=16 (the multibonds of arms: generalized
/// coordinates, pin velocities) and say whether it did; wider bonds take the general path.
macro_rules! fixed_width {
    ($dim:expr, $f:ident, $($arg:expr),*) => {
        match $dim {
            2 => { $f::<2>($($arg),*); true }
            3 => { $f::<3>($($arg),*); true }
            4 => { $f::<4>($($arg),*); true }
            5 => { $f::<5>($($arg),*); true }
            6 => { $f::<6>($($arg),*); true }
            7 => { $f::<7>($($arg),*); true }
            8 => { $f::<8>($($arg),*); true }
            9 => { $f::<9>($($arg),*); true }
            10 => { $f::<10>($($arg),*); true }
            11 => { $f::<11>($($arg),*); true }
            12 => { $f::<12>($($arg),*); true }
            13 => { $f::<13>($($arg),*); true }
            14 => { $f::<14>($($arg),*); true }
            15 => { $f::<15>($($arg),*); true }
            16 => { $f::<16>($($arg),*); true }
            _ => false,
        }
    };
}

fn two_stages(
    causality: &[PortCausality],
    dominant_c: PortCausality,
    common: fn(usize) -> Slot,
    summed: fn(usize) -> Slot,
) -> Vec<Stage> {
    let d = causality.iter().position(|&c| c == dominant_c).unwrap_or(0);
    let others: Vec<usize> = (0..causality.len()).filter(|&p| p != d).collect();
    vec![
        Stage {
            writes: others.iter().map(|&p| common(p)).collect(),
            reads: vec![common(d)],
        },
        Stage {
            writes: vec![summed(d)],
            reads: others.iter().map(|&p| summed(p)).collect(),
        },
    ]
}

/// Copy port `d`'s values (efforts of a 0-, flows of a 1-junction) to every other port.
fn share(values: &mut [f64], layout: &Layout, d: usize) {
    let (from, dim) = (layout.ports[d].offset, layout.ports[d].dim);
    if dim == 1 {
        // scalar bonds (most junctions): plain stores, no memmove per port
        let v = values[from];
        for (p, port) in layout.ports.iter().enumerate() {
            if p != d {
                values[port.offset] = v;
            }
        }
        return;
    }
    if fixed_width!(dim, share_n, values, layout, d) {
        return;
    }
    for (p, port) in layout.ports.iter().enumerate() {
        if p != d {
            values.copy_within(from..from + dim, port.offset);
        }
    }
}

/// [`share`] for bonds of dimension `N`: fixed-size copies (no memmove call per port).
fn share_n<const N: usize>(values: &mut [f64], layout: &Layout, d: usize) {
    let from = layout.ports[d].offset;
    let mut v = [0.0; N];
    v.copy_from_slice(&values[from..from + N]);
    for (p, port) in layout.ports.iter().enumerate() {
        if p != d {
            values[port.offset..port.offset + N].copy_from_slice(&v);
        }
    }
}

/// [`balance`] for bonds of dimension `N`: the sums 0 + s₁v₁ + s₂v₂ + … (ports in order,
/// as in place) formed in a fixed-size array.
fn balance_n<const N: usize>(values: &mut [f64], layout: &Layout, d: usize) {
    let (to, sd) = (layout.ports[d].offset, layout.ports[d].sign);
    let mut sum = [0.0; N];
    for (p, port) in layout.ports.iter().enumerate() {
        if p != d {
            let s = -sd * port.sign;
            let mut v = [0.0; N];
            v.copy_from_slice(&values[port.offset..port.offset + N]);
            for (a, x) in sum.iter_mut().zip(v) {
                *a += s * x;
            }
        }
    }
    values[to..to + N].copy_from_slice(&sum);
}

/// Set port `d`'s values so that Σ_p s_p v_p = 0 (the flows of a 0-, the efforts of a
/// 1-junction, s_p = ±1 the half-arrow's direction).
fn balance(values: &mut [f64], layout: &Layout, d: usize) {
    let (to, dim, sd) = (
        layout.ports[d].offset,
        layout.ports[d].dim,
        layout.ports[d].sign,
    );
    if dim == 1 {
        // scalar bonds: the same sum, in the same order, in a register
        let mut sum = 0.0;
        for (p, port) in layout.ports.iter().enumerate() {
            if p != d {
                sum += -sd * port.sign * values[port.offset];
            }
        }
        values[to] = sum;
        return;
    }
    if fixed_width!(dim, balance_n, values, layout, d) {
        return;
    }
    values[to..to + dim].fill(0.0);
    for (p, port) in layout.ports.iter().enumerate() {
        if p != d {
            let s = -sd * port.sign;
            for k in 0..dim {
                values[to + k] += s * values[port.offset + k];
            }
        }
    }
}

/// 0-junction (common effort, parallel connection, Kirchhoff's current law).
#[derive(Debug, Default)]
pub struct ZeroJunction;

impl Element for ZeroJunction {
    fn kind(&self) -> &str {
        "0"
    }
    fn ports(&self) -> Ports {
        Ports::Any
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::ExactlyOne(PortCausality::FlowOut)
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        two_stages(causality, PortCausality::FlowOut, Slot::Effort, Slot::Flow)
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let d = dominant(io, PortCausality::FlowOut);
        if stage == 0 {
            share(io.effort, io.layout, d);
        } else {
            // f_in(d) = −Σ f_in(p): on the bond values, flow(d) = −s_d Σ s_p flow(p).
            balance(io.flow, io.layout, d);
        }
    }
    fn partials_are_constant(&self) -> bool {
        true
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let d = dominant(io, PortCausality::FlowOut);
        for k in 0..io.dim(d) {
            for p in (0..io.n_ports()).filter(|&p| p != d) {
                if stage == 0 {
                    jac.set(jac.row(Slot::Effort(p), k), jac.effort_col(d, k), 1.0);
                } else {
                    jac.set(jac.row(Slot::Flow(d), k), jac.flow_col(p, k), -1.0);
                }
            }
        }
        true
    }
}

/// 1-junction (common flow, series connection, Kirchhoff's voltage law / force balance).
#[derive(Debug, Default)]
pub struct OneJunction;

impl Element for OneJunction {
    fn kind(&self) -> &str {
        "1"
    }
    fn ports(&self) -> Ports {
        Ports::Any
    }
    fn causal_rule(&self, _: usize) -> CausalRule {
        CausalRule::ExactlyOne(PortCausality::EffortOut)
    }
    fn stages(&self, causality: &[PortCausality]) -> Vec<Stage> {
        two_stages(
            causality,
            PortCausality::EffortOut,
            Slot::Flow,
            Slot::Effort,
        )
    }
    fn eval(&self, stage: usize, io: &mut Io<'_>) {
        let d = dominant(io, PortCausality::EffortOut);
        if stage == 0 {
            // The bond variables share one flow whatever the half-arrows say.
            share(io.flow, io.layout, d);
        } else {
            // Σ s_p e_p = 0 over all ports (s: +1 into the junction).
            balance(io.effort, io.layout, d);
        }
    }
    fn partials_are_constant(&self) -> bool {
        true
    }
    fn stage_partials(&self, stage: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
        let d = dominant(io, PortCausality::EffortOut);
        let sd = io.sign(d);
        for k in 0..io.dim(d) {
            for p in (0..io.n_ports()).filter(|&p| p != d) {
                let sp = io.sign(p);
                if stage == 0 {
                    jac.set(jac.row(Slot::Flow(p), k), jac.flow_col(d, k), sp * sd);
                } else {
                    jac.set(jac.row(Slot::Effort(d), k), jac.effort_col(p, k), -sd * sp);
                }
            }
        }
        true
    }
}

/// Kind `0`: common effort, flows sum to zero.
pub const ZERO: KindDecl = KindDecl::element(
    "0",
    "0-junction: common effort, flows sum to zero",
    &[],
    |_| Ok(Box::new(ZeroJunction)),
);

/// Kind `1`: common flow, efforts sum to zero.
pub const ONE: KindDecl = KindDecl::element(
    "1",
    "1-junction: common flow, efforts sum to zero",
    &[],
    |_| Ok(Box::new(OneJunction)),
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_partials;
    use crate::element::PortLayout;

    /// The in-place `share` and `balance` before the fixed-width paths (the reference).
    fn share_ref(values: &mut [f64], layout: &Layout, d: usize) {
        let (from, dim) = (layout.ports[d].offset, layout.ports[d].dim);
        for (p, port) in layout.ports.iter().enumerate() {
            if p != d {
                values.copy_within(from..from + dim, port.offset);
            }
        }
    }
    fn balance_ref(values: &mut [f64], layout: &Layout, d: usize) {
        let (to, dim, sd) = (
            layout.ports[d].offset,
            layout.ports[d].dim,
            layout.ports[d].sign,
        );
        values[to..to + dim].fill(0.0);
        for (p, port) in layout.ports.iter().enumerate() {
            if p != d {
                let s = -sd * port.sign;
                for k in 0..dim {
                    values[to + k] += s * values[port.offset + k];
                }
            }
        }
    }

    #[test]
    fn share_and_balance_are_bit_identical_to_the_in_place_loops() {
        // widths 1 (scalar path), 2..=16 (fixed-size arrays) and 17, 20 (general path);
        // 1 to 6 ports, every port dominant in turn, values of mixed signs and magnitudes
        let signs = [1.0, -1.0, -1.0, 1.0, -1.0, 1.0];
        for dim in (1..=17).chain([20]) {
            for n in 1..=6 {
                let layout = Layout {
                    ports: (0..n)
                        .map(|p| PortLayout {
                            offset: 3 + p * dim,
                            dim,
                            sign: signs[p],
                            causality: PortCausality::EffortOut,
                        })
                        .collect(),
                    ..Layout::default()
                };
                let len = 3 + n * dim + 2;
                let start: Vec<f64> = (0..len)
                    .map(|k| ((k * 7919 % 113) as f64 - 56.3) * 10f64.powi((k % 9) as i32 - 4))
                    .collect();
                for d in 0..n {
                    type Routine = fn(&mut [f64], &Layout, usize);
                    let pairs: [(Routine, Routine); 2] =
                        [(share, share_ref), (balance, balance_ref)];
                    for (fast, slow) in pairs {
                        let (mut a, mut b) = (start.clone(), start.clone());
                        fast(&mut a, &layout, d);
                        slow(&mut b, &layout, d);
                        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                        assert_eq!(bits(&a), bits(&b), "dim {dim}, {n} ports, dominant {d}");
                    }
                }
            }
        }
    }

    #[test]
    fn partials_match_central_differences() {
        use PortCausality::{EffortOut as E, FlowOut as F};
        // three 2-bonds, mixed half-arrows: e, f per port (2 each)
        let point: Vec<f64> = (0..12).map(|k| 0.3 * k as f64 - 1.1).collect();
        let signs = [1.0, -1.0, 1.0];
        for d in 0..3 {
            let zero: Vec<_> = (0..3)
                .map(|p| (2, signs[p], if p == d { F } else { E }))
                .collect();
            assert_eq!(check_partials(&ZeroJunction, &zero, &point), Ok(2));
            let one: Vec<_> = (0..3)
                .map(|p| (2, signs[p], if p == d { E } else { F }))
                .collect();
            assert_eq!(check_partials(&OneJunction, &one, &point), Ok(2));
        }
    }
}
