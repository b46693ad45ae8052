//! Bonds: a power direction (the half-arrow, `from → to`), a dimension (a multibond carries
//! `n` efforts and `n` flows) and, once causality is assigned, a causal stroke.

/// Index of an element in a [`BondGraph`](crate::BondGraph).
pub type ElementId = usize;
/// Index of a bond in a [`BondGraph`](crate::BondGraph).
pub type BondId = usize;

/// One end of a bond: an element and one of its ports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Endpoint {
    /// The element.
    pub element: ElementId,
    /// Port index on that element.
    pub port: usize,
}

/// Which variable an element computes on one of its ports.
///
/// `EffortOut`: the element imposes the effort and receives the flow (the causal stroke sits
/// at the *other* end of the bond). `FlowOut`: the element receives the effort and imposes the
/// flow (the stroke sits at this element's end).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PortCausality {
    /// The element sets the effort of the bond.
    EffortOut,
    /// The element sets the flow of the bond.
    FlowOut,
}

impl PortCausality {
    /// The causality seen from the other end of the bond.
    #[must_use]
    pub fn opposite(self) -> Self {
        match self {
            Self::EffortOut => Self::FlowOut,
            Self::FlowOut => Self::EffortOut,
        }
    }
}

/// A bond from `from` to `to`: positive power `e·f` flows in that direction (the half-arrow).
#[derive(Clone, Debug)]
pub struct Bond {
    /// Name used in messages and outputs (`b1`, `b2`, … unless given).
    pub name: String,
    /// Tail of the half-arrow.
    pub from: Endpoint,
    /// Head of the half-arrow.
    pub to: Endpoint,
    /// Number of effort/flow pairs carried (1 for a scalar bond).
    pub dim: usize,
}

impl Bond {
    /// The end attached to `element`, if any (`true` = head).
    #[must_use]
    pub fn end_of(&self, element: ElementId) -> Option<Endpoint> {
        if self.from.element == element {
            Some(self.from)
        } else if self.to.element == element {
            Some(self.to)
        } else {
            None
        }
    }
}
