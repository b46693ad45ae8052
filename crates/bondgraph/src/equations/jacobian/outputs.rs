//! ∂y/∂x of any probe, exact: the Jacobian pass over the *whole* plan (output-only stages
//! included), each probe's row read from the gradient workspace.

use nalgebra::DMatrix;

use super::pass::{write_rows, Pass, Work};
use super::Out;
use crate::equations::{Probe, StateEquations};

impl StateEquations {
    /// ∂f/∂x at (t, x) into `jac` (as [`jacobian`](Self::jacobian)) and, into row k of
    /// `out`, the gradient ∂yₖ/∂x of `probes[k]`: exact where the elements give their
    /// partials, differenced element by element where they do not, as the Jacobian.
    ///
    /// `jac` is resized to n×n and `out` to (probes)×n if they are not already. Not for the
    /// solver's inner loop: it evaluates the output-only stages too and allocates its
    /// workspace.
    pub fn output_jacobian(
        &self,
        t: f64,
        x: &[f64],
        probes: &[Probe],
        jac: &mut DMatrix<f64>,
        out: &mut DMatrix<f64>,
    ) {
        self.linear_jacobians(t, x, &[], probes, jac, out);
    }

    /// As [`output_jacobian`](Self::output_jacobian), with m more columns: the derivatives
    /// with respect to the signals at offsets `seeds` (an external input's value,
    /// [`Probe::Signal`]), each taken as an independent variable — after the stage that
    /// writes it, its gradient is the unit vector of its own column n + k, and the chain rule
    /// carries it through every stage that reads it. `jac` receives [∂f/∂x ∂f/∂u] (n×(n+m)),
    /// `out` [∂y/∂x ∂y/∂u] (probes×(n+m)).
    pub fn linear_jacobians(
        &self,
        t: f64,
        x: &[f64],
        seeds: &[usize],
        probes: &[Probe],
        jac: &mut DMatrix<f64>,
        out: &mut DMatrix<f64>,
    ) {
        let n = self.states.len();
        let width = n + seeds.len();
        if jac.shape() != (n, width) {
            *jac = DMatrix::zeros(n, width);
        }
        if out.shape() != (probes.len(), width) {
            *out = DMatrix::zeros(probes.len(), width);
        }
        jac.fill(0.0);
        out.fill(0.0);
        let code = self.compile(&self.order, seeds, t, x, None);
        let mut w = Work::new(&code, &self.states);
        let mut ws = self.ws.borrow_mut();
        // compiled at this very point: no element can leave its structure
        Pass::run(self, &code, &mut w, &mut ws, t, x);
        write_rows(&code, &w, &mut Out::Dense(jac));
        let nb = self.n_bond_values;
        // Row k += scale · gradient of slot g.
        let add = |out: &mut DMatrix<f64>, k: usize, g: usize, scale: f64| {
            let src = code.slots[g];
            let scale = scale * src.scale;
            for q in src.span.range() {
                out[(k, code.cols[q] as usize)] += scale * w.g[q];
            }
        };
        for (k, p) in probes.iter().enumerate() {
            match *p {
                Probe::Time => {}
                Probe::State(i) => out[(k, i)] = 1.0,
                Probe::Derivative(i) => {
                    for j in 0..width {
                        out[(k, j)] = jac[(i, j)];
                    }
                }
                Probe::Effort(o) => add(out, k, o, 1.0),
                Probe::Flow(o) => add(out, k, nb + o, 1.0),
                Probe::Signal(o) => add(out, k, 2 * nb + o, 1.0),
                Probe::Power(b) => {
                    // P = Σ e·f: ∇P = Σ f∇e + e∇f.
                    let (o, d) = (self.bond_offset[b], self.graph.bond(b).dim);
                    for c in o..o + d {
                        add(out, k, c, ws.flow[c]);
                        add(out, k, nb + c, ws.effort[c]);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)] // exact values by intent
    use nalgebra::DMatrix;

    /// Every probe of a mass–spring–damper against central differences of `read`.
    #[test]
    fn probe_gradients_match_differences() {
        let eqs = crate::test_models::msd(2.0, 0.02, 3.0, 3.0, None);
        let names = eqs.probe_names();
        let probes: Vec<_> = names.iter().map(|n| eqs.probe(n).unwrap()).collect();
        let x = [0.7, -0.3];
        let (mut jac, mut c) = (DMatrix::zeros(0, 0), DMatrix::zeros(0, 0));
        eqs.output_jacobian(0.0, &x, &probes, &mut jac, &mut c);
        let mut a = DMatrix::zeros(2, 2);
        eqs.jacobian(0.0, &x, &mut a);
        assert_eq!(jac, a);
        let read = |x: &[f64], k: usize| {
            eqs.evaluate(0.0, x);
            eqs.read(probes[k], 0.0, x)
        };
        let mut worst = 0.0f64;
        for k in 0..probes.len() {
            for j in 0..2 {
                let h = 1e-6;
                let (mut xp, mut xm) = (x, x);
                xp[j] += h;
                xm[j] -= h;
                let fd = (read(&xp, k) - read(&xm, k)) / (2.0 * h);
                let err = (c[(k, j)] - fd).abs() / fd.abs().max(1.0);
                worst = worst.max(err);
                assert!(err < 1e-7, "{}: ∂/∂x{j} = {} vs {fd}", names[k], c[(k, j)]);
            }
        }
        eprintln!(
            "{} probes: worst relative difference {worst:.1e}",
            probes.len()
        );
    }
}
