//! What an element sees while it is evaluated ([`Io`]): its ports' efforts and flows, its
//! signal inputs and outputs, its states and time, and where each lives ([`Layout`]). Shared
//! by the evaluation plan, the elements and their local Jacobians.

use crate::bond::PortCausality;

/// A variable an element reads or writes: a port's effort or flow, a signal input or output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Slot {
    /// Effort of port `i`.
    Effort(usize),
    /// Flow of port `i`.
    Flow(usize),
    /// Signal input `i`.
    Input(usize),
    /// Signal output `i`.
    Output(usize),
}

/// Where a signal input comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// Simulation time.
    Time,
    /// A state, at this offset in the state vector.
    State(usize),
    /// A published signal, at this offset in the signal array.
    Signal(usize),
    /// A bond's effort, at this offset in the effort array.
    Effort(usize),
    /// A bond's flow, at this offset in the flow array.
    Flow(usize),
}

/// Port layout: where a port's bond lives in the effort/flow arrays.
#[derive(Clone, Debug)]
pub struct PortLayout {
    /// Offset of the bond's values.
    pub offset: usize,
    /// Bond dimension.
    pub dim: usize,
    /// +1 if the half-arrow points into this element, −1 if it points away.
    pub sign: f64,
    /// Causality of this port.
    pub causality: PortCausality,
}

/// Where everything an element touches lives.
#[derive(Clone, Debug, Default)]
pub struct Layout {
    /// Ports in order.
    pub ports: Vec<PortLayout>,
    /// Signal inputs: source and dimension.
    pub inputs: Vec<(Source, usize)>,
    /// Signal outputs: offset in the signal array and dimension.
    pub outputs: Vec<(usize, usize)>,
    /// Offset of this element's states in the state vector.
    pub state_offset: usize,
    /// Number of states.
    pub n_states: usize,
}

/// What an element sees while it is evaluated.
pub struct Io<'a> {
    pub(crate) t: f64,
    pub(crate) x: &'a [f64],
    pub(crate) effort: &'a mut [f64],
    pub(crate) flow: &'a mut [f64],
    pub(crate) signals: &'a mut [f64],
    pub(crate) layout: &'a Layout,
}

impl<'a> Io<'a> {
    /// Simulation time.
    #[inline]
    #[must_use]
    pub fn time(&self) -> f64 {
        self.t
    }
    /// This element's states.
    #[inline]
    #[must_use]
    pub fn states(&self) -> &[f64] {
        let l = self.layout;
        &self.x[l.state_offset..l.state_offset + l.n_states]
    }
    /// Number of ports.
    #[inline]
    #[must_use]
    pub fn n_ports(&self) -> usize {
        self.layout.ports.len()
    }
    /// Dimension of port `port`.
    #[inline]
    #[must_use]
    pub fn dim(&self, port: usize) -> usize {
        self.layout.ports[port].dim
    }
    /// +1 if the bond at `port` points into the element, −1 otherwise.
    #[inline]
    #[must_use]
    pub fn sign(&self, port: usize) -> f64 {
        self.layout.ports[port].sign
    }
    /// Causality of `port`.
    #[inline]
    #[must_use]
    pub fn causality(&self, port: usize) -> PortCausality {
        self.layout.ports[port].causality
    }
    /// Effort vector of `port`.
    #[inline]
    #[must_use]
    pub fn effort(&self, port: usize) -> &[f64] {
        let p = &self.layout.ports[port];
        &self.effort[p.offset..p.offset + p.dim]
    }
    /// Flow vector of `port` (the bond's flow, in the half-arrow's direction).
    #[inline]
    #[must_use]
    pub fn flow(&self, port: usize) -> &[f64] {
        let p = &self.layout.ports[port];
        &self.flow[p.offset..p.offset + p.dim]
    }
    /// Component `k` of the effort at `port`.
    #[inline]
    #[must_use]
    pub fn e(&self, port: usize, k: usize) -> f64 {
        self.effort[self.layout.ports[port].offset + k]
    }
    /// Component `k` of the flow *into the element* at `port`.
    #[inline]
    #[must_use]
    pub fn f_in(&self, port: usize, k: usize) -> f64 {
        let p = &self.layout.ports[port];
        p.sign * self.flow[p.offset + k]
    }
    /// Set component `k` of the effort at `port`.
    #[inline]
    pub fn set_e(&mut self, port: usize, k: usize, value: f64) {
        let off = self.layout.ports[port].offset;
        self.effort[off + k] = value;
    }
    /// Set component `k` of the flow *into the element* at `port`.
    #[inline]
    pub fn set_f_in(&mut self, port: usize, k: usize, value: f64) {
        let p = &self.layout.ports[port];
        self.flow[p.offset + k] = p.sign * value;
    }
    /// Signal input `i` (a slice of its dimension).
    #[inline]
    #[must_use]
    pub fn input(&self, i: usize) -> &[f64] {
        let (src, dim) = self.layout.inputs[i];
        match src {
            Source::Time => std::slice::from_ref(&self.t),
            Source::State(o) => &self.x[o..o + dim],
            Source::Signal(o) => &self.signals[o..o + dim],
            Source::Effort(o) => &self.effort[o..o + dim],
            Source::Flow(o) => &self.flow[o..o + dim],
        }
    }
    /// First component of signal input `i`.
    #[inline(always)]
    #[must_use]
    pub fn u(&self, i: usize) -> f64 {
        // `input(i)[0]` without forming the slice
        let (src, dim) = self.layout.inputs[i];
        assert!(dim > 0 || src == Source::Time, "empty signal input");
        match src {
            Source::Time => self.t,
            Source::State(o) => self.x[o],
            Source::Signal(o) => self.signals[o],
            Source::Effort(o) => self.effort[o],
            Source::Flow(o) => self.flow[o],
        }
    }
    /// Set signal output `i` (component `k`).
    #[inline]
    pub fn set_y(&mut self, i: usize, k: usize, value: f64) {
        let (off, _) = self.layout.outputs[i];
        self.signals[off + k] = value;
    }
}
