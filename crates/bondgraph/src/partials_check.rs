//! [`check_partials`]: an element's analytic partials against central differences of its
//! own `eval`, in isolation — the test every element with `stage_partials` runs.

use crate::bond::PortCausality;
use crate::element::Element;
use crate::io::{Io, Layout, PortLayout, Slot, Source};
use crate::local_jacobian::{LocalJacobian, LocalShape};

/// An element in isolation, at one point of its local variables: what
/// [`check_partials`] evaluates.
struct Bench<'e> {
    element: &'e dyn Element,
    layout: Layout,
    shape: LocalShape,
    effort: Vec<f64>,
    flow: Vec<f64>,
    signals: Vec<f64>,
    x: Vec<f64>,
}

impl Bench<'_> {
    fn io(&mut self) -> Io<'_> {
        Io {
            t: 0.0,
            x: &self.x,
            effort: &mut self.effort,
            flow: &mut self.flow,
            signals: &mut self.signals,
            layout: &self.layout,
        }
    }

    /// Set the storage of local column `c` to `v` (the columns' convention: `f_in` flows).
    fn set(&mut self, c: usize, v: f64) {
        let cell = self.cell(c);
        match cell {
            (0, o, _) => self.effort[o] = v,
            (1, o, s) => self.flow[o] = s * v,
            (2, o, _) => self.signals[o] = v,
            (_, o, _) => self.x[o] = v,
        }
    }

    fn get(&self, c: usize) -> f64 {
        match self.cell(c) {
            (0, o, _) => self.effort[o],
            (1, o, s) => s * self.flow[o],
            (2, o, _) => self.signals[o],
            (_, o, _) => self.x[o],
        }
    }

    /// (array, offset, sign) of local column `c`: 0 effort, 1 flow, 2 signal, 3 state.
    fn cell(&self, c: usize) -> (u8, usize, f64) {
        for (p, &(start, dim)) in self.shape.ports.iter().enumerate() {
            let port = &self.layout.ports[p];
            if c < start + dim {
                return (0, port.offset + c - start, 1.0);
            }
            if c < start + 2 * dim {
                return (1, port.offset + c - start - dim, port.sign);
            }
        }
        for (i, &(start, dim)) in self.shape.inputs.iter().enumerate() {
            if c < start + dim {
                let Source::Signal(o) = self.layout.inputs[i].0 else {
                    unreachable!("the bench feeds every input from a signal")
                };
                return (2, o + c - start, 1.0);
            }
        }
        (3, c - self.shape.states, 1.0)
    }

    /// The values of a block's rows: a stage's writes (`f_in` for flows), or the derivatives.
    fn rows(&mut self, stage: Option<usize>, shape: &LocalShape, out: &mut [f64]) {
        match stage {
            Some(s) => {
                let element = self.element;
                let mut io = self.io();
                element.eval(s, &mut io);
                for &(slot, r, dim) in shape.rows() {
                    for k in 0..dim {
                        out[r + k] = match slot {
                            Slot::Effort(p) => io.e(p, k),
                            Slot::Flow(p) => io.f_in(p, k),
                            Slot::Output(i) | Slot::Input(i) => {
                                io.signals[io.layout.outputs[i].0 + k]
                            }
                        };
                    }
                }
            }
            None => {
                let element = self.element;
                let io = self.io();
                element.derivatives(&io, out);
            }
        }
    }
}

/// Check an element's analytic partials ([`Element::stage_partials`],
/// [`Element::derivative_partials`]) against central differences of its own `eval` and
/// `derivatives`, at one point of its local variables: the test every element with partials
/// should have.
///
/// # Arguments
/// * `element` — the element.
/// * `ports` — per port: dimension, half-arrow sign (+1 into the element, −1 away) and
///   causality.
/// * `point` — a value for every local column, in [`LocalJacobian`]'s column order (efforts,
///   flows in, inputs, states). Entries a stage writes are overwritten by that stage.
///
/// Each column is stepped by ∛ε·max(|v|, 1e-3): give columns whose natural scale is large
/// (pressures) values of that scale, not zero.
///
/// # Returns
/// The number of blocks (stages, then the derivatives if the element has states) that gave
/// partials, or the first entry that differs:
/// `|J − J_fd|·s_c > 1e-6·(|J_fd|·s_c + maxₖ |J_fd,rk|·s_k)` with `s_c = max(|v_c|, 1e-3)`.
pub fn check_partials(
    element: &dyn Element,
    ports: &[(usize, f64, PortCausality)],
    point: &[f64],
) -> Result<usize, String> {
    let mut layout = Layout::default();
    let mut off = 0;
    for &(dim, sign, causality) in ports {
        layout.ports.push(PortLayout {
            offset: off,
            dim,
            sign,
            causality,
        });
        off += dim;
    }
    let mut n_signals = 0;
    for s in element.signal_inputs() {
        layout.inputs.push((Source::Signal(n_signals), s.dim));
        n_signals += s.dim;
    }
    for s in element.signal_outputs() {
        layout.outputs.push((n_signals, s.dim));
        n_signals += s.dim;
    }
    layout.n_states = element.states().len();
    let columns = LocalShape::columns(&layout);
    if point.len() != columns.n_cols {
        return Err(format!(
            "{} values for {} local columns",
            point.len(),
            columns.n_cols
        ));
    }
    let mut bench = Bench {
        element,
        shape: columns,
        effort: vec![0.0; off],
        flow: vec![0.0; off],
        signals: vec![0.0; n_signals],
        x: vec![0.0; layout.n_states],
        layout,
    };
    let reset = |b: &mut Bench<'_>| {
        for (c, &v) in point.iter().enumerate() {
            b.set(c, v);
        }
    };
    let causality: Vec<PortCausality> = ports.iter().map(|p| p.2).collect();
    let stages = element.stages(&causality);
    let mut blocks: Vec<(Option<usize>, LocalShape)> = stages
        .iter()
        .enumerate()
        .map(|(s, st)| (Some(s), LocalShape::stage(&bench.layout, &st.writes)))
        .collect();
    if bench.layout.n_states > 0 {
        blocks.push((None, LocalShape::derivatives(&bench.layout)));
    }
    let mut given = 0;
    for (stage, shape) in &blocks {
        let (m, nc) = (shape.n_rows(), shape.n_cols());
        let mut values = vec![0.0; shape.len()];
        reset(&mut bench);
        let mut base = vec![0.0; m];
        bench.rows(*stage, shape, &mut base);
        let ok = {
            let mut jac = LocalJacobian::new(shape, &mut values);
            let io = bench.io();
            match stage {
                Some(s) => element.stage_partials(*s, &io, &mut jac),
                None => element.derivative_partials(&io, &mut jac),
            }
        };
        if !ok {
            continue;
        }
        given += 1;
        let mut fd = vec![0.0; m * nc];
        let (mut plus, mut minus) = (vec![0.0; m], vec![0.0; m]);
        let scale: Vec<f64> = point.iter().map(|v| v.abs().max(1e-3)).collect();
        for c in 0..nc {
            reset(&mut bench);
            let v = bench.get(c);
            let h = crate::element::central_step(v, 1e-3);
            bench.set(c, v + h);
            bench.rows(*stage, shape, &mut plus);
            reset(&mut bench);
            bench.set(c, v - h);
            bench.rows(*stage, shape, &mut minus);
            for r in 0..m {
                fd[r * nc + c] = (plus[r] - minus[r]) / (2.0 * h);
            }
        }
        for r in 0..m {
            let row = (0..nc)
                .map(|k| fd[r * nc + k].abs() * scale[k])
                .fold(0.0, f64::max);
            for c in 0..nc {
                let (a, d) = (values[r * nc + c], fd[r * nc + c]);
                if (a - d).abs() * scale[c] > 1e-6 * (d.abs() * scale[c] + row) || a.is_nan() {
                    return Err(format!(
                        "{} {}: ∂(row {r})/∂(column {c}) = {a:e}, central differences {d:e}",
                        element.kind(),
                        stage.map_or("derivatives".to_owned(), |s| format!("stage {s}")),
                    ));
                }
            }
        }
    }
    Ok(given)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::{CausalRule, PortSpec, Ports};
    use crate::io::Slot;

    /// e = f_in², with a partial `2·f_in·scale`.
    #[derive(Debug)]
    struct Square(f64);

    impl Element for Square {
        fn kind(&self) -> &str {
            "square"
        }
        fn ports(&self) -> Ports {
            Ports::Fixed(vec![PortSpec::new("1", 1)])
        }
        fn causal_rule(&self, _: usize) -> CausalRule {
            CausalRule::Resistive(vec![vec![PortCausality::EffortOut]])
        }
        fn eval(&self, _: usize, io: &mut Io<'_>) {
            let f = io.f_in(0, 0);
            io.set_e(0, 0, f * f);
        }
        fn stage_partials(&self, _: usize, io: &Io<'_>, jac: &mut LocalJacobian<'_>) -> bool {
            let (r, c) = (jac.row(Slot::Effort(0), 0), jac.flow_col(0, 0));
            jac.set(r, c, 2.0 * io.f_in(0, 0) * self.0);
            true
        }
    }

    #[test]
    fn check_partials_accepts_right_and_names_wrong_partials() {
        let port = [(1, -1.0, PortCausality::EffortOut)];
        assert_eq!(check_partials(&Square(1.0), &port, &[0.0, 1.3]), Ok(1));
        let e = check_partials(&Square(1.01), &port, &[0.0, 1.3]).unwrap_err();
        assert!(e.contains("stage 0") && e.contains("column 1"), "{e}");
        assert!(check_partials(&Square(1.0), &port, &[0.0]).is_err());
    }
}
