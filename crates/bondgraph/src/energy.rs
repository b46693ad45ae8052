//! Where the energy of a run goes: a power audit of every element ([`EnergyAudit`]), integrated
//! alongside the run, and its result ([`EnergyReport`], one [`ElementEnergy`] per element).
//!
//! Every element sees its ports with power in positive (`docs/conventions.md`), so the power
//! into element i is `P_i = Σ_ports sign·e·f` ([`StateEquations::power_into`]). What that power
//! does depends on what the element is, its [`EnergyRole`] ([`Element::energy_role`](crate::Element::energy_role)):
//!
//! | role | what its ∫P_i dt is | examples |
//! |---|---|---|
//! | [`EnergyRole::Source`] | −supplied (a source driven from outside the graph, [`Element::external_power`](crate::Element::external_power): supplied = ∫P_ext dt, its own losses ∫(P_ext + P) dt) | Se, Sf, a pump driven at its outlet, the crane's valve (from its supply), gravity |
//! | [`EnergyRole::Storage`] | stored (E(end) − E(start) from [`Element::stored_energy`](crate::Element::stored_energy) where the element has one) | C, I, the arm's I- and C-fields, chambers, accumulators, lines |
//! | [`EnergyRole::LossyStorage`] | stored = E(end) − E(start), dissipated = ∫P dt − stored | a line of C–R–I segments |
//! | [`EnergyRole::Dissipation`] | dissipated | R, orifices, valves, leakage, friction, a machine's losses, modal damping |
//! | [`EnergyRole::Conservative`] | ≈ 0, checked | 0/1 junctions, TF, GY, MTF, the piston |
//! | [`EnergyRole::Signal`] | — (no ports) | signal blocks, inputs |
//!
//! Since every bond's power enters one element and leaves another, Σ_i P_i = 0 at every
//! instant; the balance `supplied − stored − dissipated` therefore measures what is not
//! bookkeeping: each storage's energy function against the integral of its port power (the
//! quadrature and the solver's error), and the power lost by elements that should conserve
//! it.
//!
//! ## Quadrature
//! After each accepted step [t₀, t₁] the audit evaluates the power at the three Radau IIA
//! nodes t₀ + cₖ·h on the method's dense output and adds Σ bₖ·h·P(t₀ + cₖh) (weights of the
//! 3-stage Radau quadrature, exact for polynomials of degree 4 in t). With Radau IIA (the
//! default) the dense output is the step's collocation polynomial u(t), which satisfies
//! u′ = f(u) at exactly those nodes: the quadrature of `∇E(u)·f(u)` is then the quadrature
//! of `d/dt E(u(t))`, so a storage's balance closes to the quadrature's order (exactly for a
//! quadratic energy and a linear model) and the Newton tolerance. No state is added, the
//! error norm and the steps are those of a run without the audit, and the audit costs three
//! evaluations of the plan per accepted step (no Jacobian, no allocation with Radau).
//! `docs/energy.md` says why and measures it.

use crate::bond::ElementId;
use crate::element::CausalRule;
use crate::equations::StateEquations;

/// What an element does with the power that enters it (see the module's table).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EnergyRole {
    /// Brings energy into the model from outside (Se, Sf, a driven shaft, gravity).
    Source,
    /// Stores it (C, I, fields, chambers).
    Storage,
    /// Stores part of it and dissipates the rest inside (a line of C–R–I segments): its
    /// [`stored_energy`](crate::Element::stored_energy) gives the stored part, the rest of
    /// its port power is dissipated.
    LossyStorage,
    /// Turns it into heat (R, orifices, valves, friction, damping).
    Dissipation,
    /// Passes it on (junctions, TF, GY, MTF): its net power is zero.
    Conservative,
    /// Has no ports (signal blocks).
    Signal,
}

impl EnergyRole {
    /// The role's name in tables: `source`, `storage`, `dissipation`, `conservative`, `signal`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Source => "source",
            Self::Storage => "storage",
            Self::LossyStorage => "lossy storage",
            Self::Dissipation => "dissipation",
            Self::Conservative => "conservative",
            Self::Signal => "signal",
        }
    }

    /// The role an element has by its causal rule, unless it says otherwise
    /// ([`Element::energy_role`](crate::Element::energy_role)): integral causality stores, a resistive rule dissipates,
    /// junctions/TF/GY conserve, a fixed one-port is a source, a fixed multiport conserves
    /// (MTF, the piston), no ports is a signal block.
    #[must_use]
    pub fn from_rule(rule: &CausalRule) -> Self {
        match rule {
            CausalRule::Integral(_) => Self::Storage,
            CausalRule::Resistive(_) => Self::Dissipation,
            CausalRule::ExactlyOne(_) | CausalRule::AllEqual => Self::Conservative,
            CausalRule::Fixed(p) if p.len() == 1 => Self::Source,
            CausalRule::Fixed(_) => Self::Conservative,
            CausalRule::None => Self::Signal,
        }
    }
}

/// Nodes of the 3-stage Radau IIA quadrature on [0, 1].
const RADAU_C: [f64; 3] = [
    (4.0 - 2.449_489_742_783_178) / 10.0,
    (4.0 + 2.449_489_742_783_178) / 10.0,
    1.0,
];
/// Its weights.
const RADAU_B: [f64; 3] = [
    (16.0 - 2.449_489_742_783_178) / 36.0,
    (16.0 + 2.449_489_742_783_178) / 36.0,
    1.0 / 9.0,
];

/// The energy of one element over a run.
#[derive(Clone, Debug, PartialEq)]
pub struct ElementEnergy {
    /// Element name (global, `cyl1_piston_chamber`).
    pub name: String,
    /// Its kind (`hydraulics.chamber`).
    pub kind: String,
    /// The model file's entry it belongs to (a composite's name, or its own name); the
    /// loader fills it, the core sets the element's name.
    pub composite: String,
    /// What it does with energy.
    pub role: EnergyRole,
    /// Energy it brought in (sources: −∫P dt; 0 otherwise), J.
    pub supplied: f64,
    /// Energy stored at the end minus at the start (storage elements), J.
    pub stored: f64,
    /// Energy dissipated (dissipative elements: ∫P dt), J.
    pub dissipated: f64,
    /// ∫P dt, power in positive, J (for a conservative element: what it lost, ≈ 0).
    pub net: f64,
    /// Activity ∫|P| dt, J.
    pub activity: f64,
    /// Activity over the sum of every element's activity (conservative elements excluded).
    pub share: f64,
    /// ∫ max over its ports of |e·f| dt: the power passing through it (the scale of a
    /// conservative element's `net`), J.
    pub through: f64,
    /// `stored` is E(end) − E(start) of the element's energy function (else ∫P dt).
    pub stored_by_function: bool,
}

/// The energy audit of a run: every element, the totals and the balance.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnergyReport {
    /// Time the audit started (s).
    pub t_start: f64,
    /// Time it reached (s).
    pub t_end: f64,
    /// Every element with ports, in the graph's order.
    pub elements: Vec<ElementEnergy>,
    /// Σ supplied, J.
    pub supplied: f64,
    /// Σ stored, J.
    pub stored: f64,
    /// Σ dissipated, J.
    pub dissipated: f64,
    /// Σ net power of the conservative elements (should be ≈ 0), J.
    pub conservative: f64,
    /// Energy stored at the start by the elements with an energy function, J.
    pub stored_initial: f64,
    /// supplied − stored − dissipated, J.
    pub residual: f64,
    /// The energy the residual is relative to: Σ|supplied| and the activity of the
    /// storages; with no source, the initial stored energy.
    pub reference: f64,
    /// Accepted steps audited.
    pub steps: usize,
}

impl EnergyReport {
    /// |residual| / reference (0 when nothing moved).
    #[must_use]
    pub fn relative_residual(&self) -> f64 {
        if self.reference > 0.0 {
            self.residual.abs() / self.reference
        } else {
            self.residual.abs()
        }
    }

    /// The element called `name`.
    #[must_use]
    pub fn element(&self, name: &str) -> Option<&ElementEnergy> {
        self.elements.iter().find(|e| e.name == name)
    }

    /// The elements summed by composite (the model file's entries), in order of first
    /// appearance: name = the composite, kind = its members' kind if they share one, else
    /// `composite`; role = its members' role if they share one, else the role of the member
    /// with the largest activity.
    #[must_use]
    pub fn by_composite(&self) -> Vec<ElementEnergy> {
        let mut out: Vec<(ElementEnergy, f64)> = Vec::new();
        for e in &self.elements {
            if let Some((g, top)) = out.iter_mut().find(|(g, _)| g.composite == e.composite) {
                if g.kind != e.kind {
                    g.kind = "composite".into();
                }
                if e.activity > *top {
                    *top = e.activity;
                    g.role = e.role;
                }
                g.supplied += e.supplied;
                g.stored += e.stored;
                g.dissipated += e.dissipated;
                g.net += e.net;
                g.activity += e.activity;
                g.share += e.share;
                g.through += e.through;
                g.stored_by_function &= e.stored_by_function;
            } else {
                let mut g = e.clone();
                g.name = e.composite.clone();
                out.push((g, e.activity));
            }
        }
        out.into_iter().map(|(g, _)| g).collect()
    }

    /// The value of `energy.<element or composite>.<field>` (`supplied`, `stored`,
    /// `dissipated`, `net`, `activity`, `share`), or of a total `energy.<field>`
    /// (`supplied`, `stored`, `dissipated`, `residual`, `relative_residual`).
    #[must_use]
    pub fn metric(&self, name: &str) -> Option<f64> {
        let rest = name.strip_prefix("energy.")?;
        match rest {
            "supplied" => return Some(self.supplied),
            "stored" => return Some(self.stored),
            "dissipated" => return Some(self.dissipated),
            "residual" => return Some(self.residual),
            "relative_residual" => return Some(self.relative_residual()),
            _ => {}
        }
        let (who, field) = rest.rsplit_once('.')?;
        let pick = |e: &ElementEnergy| match field {
            "supplied" => Some(e.supplied),
            "stored" => Some(e.stored),
            "dissipated" => Some(e.dissipated),
            "net" => Some(e.net),
            "activity" => Some(e.activity),
            "share" => Some(e.share),
            _ => None,
        };
        if let Some(e) = self.element(who) {
            return pick(e);
        }
        self.by_composite()
            .iter()
            .find(|g| g.name == who)
            .and_then(pick)
    }
}

/// One audited element: where its states are and what it has accumulated.
#[derive(Clone, Debug)]
struct Entry {
    id: ElementId,
    role: EnergyRole,
    /// Its states' range in the state vector.
    states: std::ops::Range<usize>,
    has_function: bool,
    /// It takes power from outside the graph ([`Element::external_power`](crate::Element::external_power)).
    has_external: bool,
    /// ∫ external power dt.
    external: f64,
    net: f64,
    activity: f64,
    through: f64,
    /// Σ over segments of E(end) − E(start) (elements with an energy function).
    stored: f64,
    /// E at the current segment's start.
    e_begin: f64,
}

/// The running audit: fed by the simulation after every accepted step
/// ([`simulate_audited`](crate::simulate::simulate_audited)), read by [`EnergyAudit::report`].
#[derive(Clone, Debug)]
pub struct EnergyAudit {
    entries: Vec<Entry>,
    /// The state at a quadrature node.
    y: Vec<f64>,
    t_start: Option<f64>,
    t_end: f64,
    stored_initial: f64,
    steps: usize,
}

impl EnergyAudit {
    /// An audit of every element of `eqs` with ports (allocates here, never per step).
    #[must_use]
    pub fn new(eqs: &StateEquations) -> Self {
        let g = eqs.graph();
        let mut entries = Vec::new();
        let x0 = eqs.initial_state();
        let t0 = 0.0;
        for id in 0..g.n_elements() {
            let el = &g.node(id).element;
            let n_ports = g.ports_of(id).len();
            let role = el.energy_role(n_ports);
            if role == EnergyRole::Signal || n_ports == 0 {
                continue;
            }
            let n = eqs.states().iter().filter(|s| s.element == id).count();
            let first = eqs.state_index(id, 0).unwrap_or(0);
            let states = first..first + n;
            // whether it has one (the value, of whatever the workspace holds, is not used)
            let has_external = eqs.external_power(id, t0, &x0).is_some();
            let has_function = matches!(role, EnergyRole::Storage | EnergyRole::LossyStorage)
                && el.stored_energy(&x0[states.clone()]).is_some();
            entries.push(Entry {
                id,
                role,
                states,
                has_function,
                has_external,
                external: 0.0,
                net: 0.0,
                activity: 0.0,
                through: 0.0,
                stored: 0.0,
                e_begin: 0.0,
            });
        }
        Self {
            entries,
            y: vec![0.0; eqs.n_states()],
            t_start: None,
            t_end: 0.0,
            stored_initial: 0.0,
            steps: 0,
        }
    }

    fn energy_of(eqs: &StateEquations, e: &Entry, x: &[f64]) -> f64 {
        eqs.graph()
            .node(e.id)
            .element
            .stored_energy(&x[e.states.clone()])
            .unwrap_or(0.0)
    }

    /// A segment starts at (t, x) with the elements in force now (after an event's switch).
    pub fn begin_segment(&mut self, eqs: &StateEquations, t: f64, x: &[f64]) {
        let first = self.t_start.is_none();
        if first {
            self.t_start = Some(t);
            self.t_end = t;
        }
        for e in &mut self.entries {
            if e.has_function {
                e.e_begin = Self::energy_of(eqs, e, x);
                if first {
                    self.stored_initial += e.e_begin;
                }
            }
        }
    }

    /// The segment ends at (t, x): each storage's energy change over it, with its element.
    pub fn end_segment(&mut self, eqs: &StateEquations, t: f64, x: &[f64]) {
        self.t_end = t;
        for e in &mut self.entries {
            if e.has_function {
                e.stored += Self::energy_of(eqs, e, x) - e.e_begin;
                e.e_begin = 0.0;
            }
        }
    }

    /// Power into every audited element at (t, y), added with `weight`.
    fn add_at(&mut self, eqs: &StateEquations, t: f64, weight: f64) {
        eqs.evaluate(t, &self.y);
        for e in &mut self.entries {
            let p = eqs.power_into(e.id);
            if e.has_external {
                e.external += weight * eqs.external_power(e.id, t, &self.y).unwrap_or(0.0);
            }
            e.net += weight * p;
            e.activity += weight * p.abs();
            e.through += weight * eqs.power_scale(e.id);
        }
    }

    /// One accepted step from `t0` to `t1` (state `x1`): the power at the Radau nodes,
    /// the states there from `interpolate(t, y)` (the method's dense output).
    ///
    /// # Errors
    /// The interpolation's error, if it failed (the step is then not audited).
    pub fn step(
        &mut self,
        eqs: &StateEquations,
        t0: f64,
        t1: f64,
        x1: &[f64],
        mut interpolate: impl FnMut(f64, &mut [f64]) -> Result<(), String>,
    ) -> Result<(), String> {
        let h = t1 - t0;
        if h <= 0.0 {
            return Ok(());
        }
        for k in 0..3 {
            let t = if k == 2 { t1 } else { t0 + RADAU_C[k] * h };
            if k == 2 {
                self.y.copy_from_slice(x1);
            } else {
                interpolate(t, &mut self.y)?;
            }
            self.add_at(eqs, t, RADAU_B[k] * h);
        }
        self.steps += 1;
        self.t_end = t1;
        Ok(())
    }

    /// The audit so far: one record per element, totals and the balance.
    #[must_use]
    pub fn report(&self, eqs: &StateEquations) -> EnergyReport {
        let g = eqs.graph();
        let total_activity: f64 = self
            .entries
            .iter()
            .filter(|e| e.role != EnergyRole::Conservative)
            .map(|e| e.activity)
            .sum();
        let mut r = EnergyReport {
            t_start: self.t_start.unwrap_or(0.0),
            t_end: self.t_end,
            stored_initial: self.stored_initial,
            steps: self.steps,
            ..EnergyReport::default()
        };
        let mut storage_activity = 0.0;
        for e in &self.entries {
            let node = g.node(e.id);
            let (mut supplied, mut stored, mut dissipated) = (0.0, 0.0, 0.0);
            match e.role {
                EnergyRole::Source if e.has_external => {
                    // the drive's energy; what did not leave through the ports was lost inside
                    supplied = e.external;
                    dissipated = e.external + e.net;
                }
                EnergyRole::Source => supplied = -e.net,
                EnergyRole::Storage => {
                    stored = if e.has_function { e.stored } else { e.net };
                    storage_activity += e.activity;
                }
                EnergyRole::LossyStorage => {
                    stored = if e.has_function { e.stored } else { e.net };
                    dissipated = e.net - stored;
                    storage_activity += e.activity;
                }
                EnergyRole::Dissipation => dissipated = e.net,
                EnergyRole::Conservative => r.conservative += e.net,
                EnergyRole::Signal => {}
            }
            r.supplied += supplied;
            r.stored += stored;
            r.dissipated += dissipated;
            let share = if e.role != EnergyRole::Conservative && total_activity > 0.0 {
                e.activity / total_activity
            } else {
                0.0
            };
            r.elements.push(ElementEnergy {
                name: node.name.clone(),
                kind: node.element.kind().to_owned(),
                composite: node.name.clone(),
                role: e.role,
                supplied,
                stored,
                dissipated,
                net: e.net,
                activity: e.activity,
                share,
                through: e.through,
                stored_by_function: e.has_function,
            });
        }
        r.residual = r.supplied - r.stored - r.dissipated;
        let sources: f64 = r
            .elements
            .iter()
            .filter(|e| e.role == EnergyRole::Source)
            .map(|e| e.activity)
            .sum();
        r.reference = if sources > 0.0 {
            sources.max(storage_activity)
        } else {
            self.stored_initial.abs().max(storage_activity)
        };
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::{simulate_audited, Settings};

    /// The default roles follow the causal rules, and the basic elements get the ones the
    /// module's table says.
    #[test]
    fn roles_by_rule_and_by_element() {
        use crate::bond::PortCausality::{EffortOut, FlowOut};
        use crate::element::Element;
        assert_eq!(
            EnergyRole::from_rule(&CausalRule::Integral(vec![EffortOut])),
            EnergyRole::Storage
        );
        assert_eq!(
            EnergyRole::from_rule(&CausalRule::Resistive(vec![])),
            EnergyRole::Dissipation
        );
        assert_eq!(
            EnergyRole::from_rule(&CausalRule::Fixed(vec![EffortOut])),
            EnergyRole::Source
        );
        assert_eq!(
            EnergyRole::from_rule(&CausalRule::Fixed(vec![FlowOut, EffortOut])),
            EnergyRole::Conservative
        );
        assert_eq!(
            EnergyRole::from_rule(&CausalRule::AllEqual),
            EnergyRole::Conservative
        );
        assert_eq!(EnergyRole::from_rule(&CausalRule::None), EnergyRole::Signal);
        assert_eq!(crate::OneJunction.energy_role(3), EnergyRole::Conservative);
        assert_eq!(
            crate::Resistor::new(1.0).unwrap().energy_role(1),
            EnergyRole::Dissipation
        );
        assert_eq!(
            crate::Capacitor::new(1.0, 0.0).unwrap().energy_role(1),
            EnergyRole::Storage
        );
        assert_eq!(
            crate::EffortSource::new(1.0).energy_role(1),
            EnergyRole::Source
        );
    }

    /// Mass–spring–damper with no source: what the damper dissipates is what the spring and
    /// the mass lose, E(0) − E(end), to 1e-8 relative.
    #[test]
    fn msd_dissipates_its_initial_energy() {
        // m = 1 kg, k = 50 N/m, r = 0.5 N·s/m, no force; released from q = 0.1 m.
        let mut eqs = crate::test_models::msd(1.0, 0.02, 0.5, 0.0, None);
        eqs.set_initial("spring.q", 0.1).unwrap();
        let x0 = eqs.initial_state();
        let settings = Settings {
            t_end: 5.0,
            rtol: 1e-8,
            atol: 1e-12,
            ..Settings::default()
        };
        let e0 = eqs.stored_energy(&x0);
        assert!(e0 > 0.0);
        let mut audit = EnergyAudit::new(&eqs);
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let out = simulate_audited(
            &mut eqs,
            &x0,
            &settings,
            &[],
            vec![],
            &mut rows,
            Some(&mut audit),
        );
        assert!(out.error.is_none());
        let r = audit.report(&eqs);
        let e1 = eqs.stored_energy(&out.x_final);
        let damper = r.element("damper").unwrap().dissipated;
        assert!(damper > 0.5 * e0, "the damper took {damper} of {e0}");
        assert!(
            (damper - (e0 - e1)).abs() <= 1e-8 * e0,
            "dissipated {damper}, lost {}",
            e0 - e1
        );
        assert!(r.relative_residual() <= 1e-8, "{r:?}");
        assert!((r.stored_initial - e0).abs() <= 1e-15 * e0);
        // The junction passes power on and keeps none of it.
        let v = r
            .elements
            .iter()
            .find(|e| e.role == EnergyRole::Conservative)
            .unwrap();
        assert!(v.net.abs() <= 1e-10 * v.through, "{v:?}");
        let shares: f64 = r.elements.iter().map(|e| e.share).sum();
        assert!((shares - 1.0).abs() < 1e-12);
    }
}
