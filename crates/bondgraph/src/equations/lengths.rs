//! Geometry that cannot be assembled: two elements that declare a length along ports joined
//! by bonds, directly or through 1-junctions (one velocity, so one distance), must agree at
//! the initial state ([`Element::port_lengths`](crate::Element::port_lengths): a cylinder's
//! l0 + s0 and the distance between the pins it is attached to).

use crate::bond::ElementId;

use super::StateEquations;

/// Largest disagreement accepted between two lengths of one distance: 1 mm plus 1e-6 of the
/// length. Far below any assembly error that matters (a cylinder off by centimetres), above
/// the rounding of lengths typed to the millimetre or computed by an expression.
pub const LENGTH_TOLERANCE_ABS: f64 = 1e-3;
/// Relative part of the length tolerance (see [`LENGTH_TOLERANCE_ABS`]).
pub const LENGTH_TOLERANCE_REL: f64 = 1e-6;

/// Two lengths of one distance that disagree at the initial state.
#[derive(Clone, Debug, PartialEq)]
pub struct LengthMismatch {
    /// The first element (in graph order) and its length signal (`cyl1_piston.l`).
    pub a: (ElementId, String),
    /// Its length, m.
    pub a_length: f64,
    /// The other element and its length signal (`crane_act1.l1`).
    pub b: (ElementId, String),
    /// Its length, m.
    pub b_length: f64,
}

impl StateEquations {
    /// Every pair of declared port lengths joined by bonds (directly or through 1-junctions)
    /// that differ by more than [`LENGTH_TOLERANCE_ABS`] + [`LENGTH_TOLERANCE_REL`]·length
    /// at (t, x), after evaluating everything there. Not for the right-hand side: it
    /// allocates.
    #[must_use]
    pub fn length_mismatches(&self, t: f64, x: &[f64]) -> Vec<LengthMismatch> {
        let g = self.graph();
        // (element, port) → (signal name, signal offset)
        let mut declared = std::collections::HashMap::new();
        for id in 0..g.n_elements() {
            let node = g.node(id);
            let outputs = node.element.signal_outputs();
            for (port, k) in node.element.port_lengths() {
                let (Some(spec), Some(&(off, 1))) =
                    (outputs.get(k), self.layouts[id].outputs.get(k))
                else {
                    continue;
                };
                declared.insert((id, port), (format!("{}.{}", node.name, spec.name), off));
            }
        }
        if declared.len() < 2 {
            return Vec::new();
        }
        self.evaluate(t, x);
        let mut keys: Vec<(ElementId, usize)> = declared.keys().copied().collect();
        keys.sort_unstable();
        let mut out = Vec::new();
        for &(id, port) in &keys {
            // walk scalar bonds from (id, port) through 1-junctions
            let mut seen = vec![id];
            let mut stack: Vec<usize> = g
                .ports_of(id)
                .get(port)
                .copied()
                .flatten()
                .into_iter()
                .collect();
            let mut found = Vec::new();
            while let Some(b) = stack.pop() {
                let bond = g.bond(b);
                if bond.dim != 1 {
                    continue;
                }
                let far = if !seen.contains(&bond.to.element) {
                    bond.to
                } else if !seen.contains(&bond.from.element) {
                    bond.from
                } else {
                    continue;
                };
                seen.push(far.element);
                if let Some(d) = declared.get(&(far.element, far.port)) {
                    found.push((far.element, d));
                } else if g.node(far.element).element.kind() == "1" {
                    stack.extend(
                        g.ports_of(far.element)
                            .iter()
                            .flatten()
                            .filter(|&&o| o != b),
                    );
                }
            }
            let (name, off) = &declared[&(id, port)];
            let la = self.read(crate::Probe::Signal(*off), t, x);
            for (other, (oname, ooff)) in found {
                if other < id {
                    continue; // each pair once
                }
                let lb = self.read(crate::Probe::Signal(*ooff), t, x);
                let tol = LENGTH_TOLERANCE_ABS + LENGTH_TOLERANCE_REL * la.abs().max(lb.abs());
                if (la - lb).abs() > tol || (la - lb).is_nan() {
                    out.push(LengthMismatch {
                        a: (id, name.clone()),
                        a_length: la,
                        b: (other, oname.clone()),
                        b_length: lb,
                    });
                }
            }
        }
        out
    }
}
