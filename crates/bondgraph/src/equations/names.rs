//! Names: resolving a signal an element reads, and the probes (states, derivatives, signals,
//! efforts, flows, powers) a run can output.

use super::{Probe, StateEquations};
use crate::bond::BondId;
use crate::element::{Ports, Source};

impl StateEquations {
    /// Resolve a signal name: `t`, `<element>.<state>`, `<element>.<signal>`,
    /// `<element>.e` / `.f` (one-port), `<element>.<port>.e` / `.f`, `<bond>.e` / `.f`.
    pub(super) fn resolve(&self, name: &str) -> Option<(Source, usize)> {
        if name == "t" || name == "time" {
            return Some((Source::Time, 1));
        }
        if let Some(i) = self.states.iter().position(|s| s.name == name) {
            return Some((Source::State(i), 1));
        }
        // A vector state `x.q` names all components `x.q[0]..`.
        let comps: Vec<usize> = (0..self.states.len())
            .filter(|&i| self.states[i].name.starts_with(&format!("{name}[")))
            .collect();
        if !comps.is_empty() && comps.windows(2).all(|w| w[1] == w[0] + 1) {
            return Some((Source::State(comps[0]), comps.len()));
        }
        if let Some((_, off, dim)) = self.signal_names.iter().find(|(n, _, _)| n == name) {
            return Some((Source::Signal(*off), *dim));
        }
        let (head, var) = name.rsplit_once('.')?;
        let bond = self.bond_of(head)?;
        let (off, dim) = (self.bond_offset[bond], self.graph.bond(bond).dim);
        match var {
            "e" => Some((Source::Effort(off), dim)),
            "f" => Some((Source::Flow(off), dim)),
            _ => None,
        }
    }

    /// The bond named `head`: a bond name, a one-port element, or `<element>.<port>`.
    fn bond_of(&self, head: &str) -> Option<BondId> {
        if let Some(b) = self.graph.bonds().position(|b| b.name == head) {
            return Some(b);
        }
        if let Some(id) = self.graph.find(head) {
            let ports = self.graph.ports_of(id);
            return if ports.len() == 1 { ports[0] } else { None };
        }
        let (el, port) = head.rsplit_once('.')?;
        let id = self.graph.find(el)?;
        let p = match self.graph.node(id).element.ports() {
            Ports::Fixed(_) => self.graph.port_index(id, port).ok()?,
            Ports::Any => port.parse().ok()?,
        };
        *self.graph.ports_of(id).get(p)?
    }

    pub(super) fn suggest(&self, name: &str) -> String {
        let el = name.split('.').next().unwrap_or(name);
        let mut names: Vec<String> = self
            .probe_names()
            .into_iter()
            .filter(|n| n.starts_with(&format!("{el}.")))
            .collect();
        names.truncate(12);
        if names.is_empty() {
            format!("no element `{el}`; signals are written `<element>.<state or signal>`, `<element>.e`, `<element>.f` or `t`")
        } else {
            format!("`{el}` offers: {}", names.join(", "))
        }
    }

    /// Every name [`probe`](Self::probe) accepts.
    #[must_use]
    pub fn probe_names(&self) -> Vec<String> {
        let mut names = vec!["t".to_owned()];
        names.extend(self.states.iter().map(|s| s.name.clone()));
        names.extend(self.states.iter().map(|s| format!("{}.dot", s.name)));
        for (n, _, d) in &self.signal_names {
            if *d == 1 {
                names.push(n.clone());
            } else {
                names.extend((0..*d).map(|k| format!("{n}[{k}]")));
            }
        }
        for id in 0..self.graph.n_elements() {
            let node = self.graph.node(id);
            let ports = self.graph.ports_of(id);
            for p in 0..ports.len() {
                let head = if ports.len() == 1 {
                    node.name.clone()
                } else {
                    format!("{}.{}", node.name, self.graph.port_name(id, p))
                };
                names.extend(["e", "f", "P"].iter().map(|v| format!("{head}.{v}")));
            }
        }
        for b in self.graph.bonds() {
            names.extend(["e", "f", "P"].iter().map(|v| format!("{}.{v}", b.name)));
        }
        names
    }

    /// Resolve an output name: `t`, a state (`mass.p`), its derivative (`mass.p.dot`), a
    /// signal (`ctrl.out`), or a bond variable `.e`, `.f`, `.P` (power) named by bond
    /// (`b3.e`), one-port element (`mass.f`) or element port (`lever.2.e`). Vector variables
    /// take a component index: `arm.q[1]`, `b4.e[2]`.
    #[must_use]
    pub fn probe(&self, name: &str) -> Option<Probe> {
        if name == "t" || name == "time" {
            return Some(Probe::Time);
        }
        if let Some(i) = self.states.iter().position(|s| s.name == name) {
            return Some(Probe::State(i));
        }
        if let Some(base) = name.strip_suffix(".dot") {
            if let Some(i) = self.states.iter().position(|s| s.name == base) {
                return Some(Probe::Derivative(i));
            }
        }
        let (base, k) = split_index(name);
        if let Some((_, off, dim)) = self.signal_names.iter().find(|(n, _, _)| n == base) {
            return (k < *dim).then_some(Probe::Signal(off + k));
        }
        let (head, var) = base.rsplit_once('.')?;
        let b = self.bond_of(head)?;
        let (off, dim) = (self.bond_offset[b], self.graph.bond(b).dim);
        match var {
            "e" if k < dim => Some(Probe::Effort(off + k)),
            "f" if k < dim => Some(Probe::Flow(off + k)),
            "P" => Some(Probe::Power(b)),
            _ => None,
        }
    }
}

fn split_index(name: &str) -> (&str, usize) {
    if let Some(stripped) = name.strip_suffix(']') {
        if let Some((base, idx)) = stripped.rsplit_once('[') {
            if let Ok(k) = idx.parse() {
                return (base, k);
            }
        }
    }
    (name, 0)
}
