//! [`Registry`]: the element kinds a model file may name, each a [`KindDecl`] — its
//! parameters declared as data and its builder. Domain crates hand theirs over as one list
//! (`registry.add(bg_hydraulics::KINDS)`) without touching the loader.

use bondgraph::KindDecl;
use indexmap::IndexMap;

/// Element kinds by name.
#[derive(Clone, Debug, Default)]
pub struct Registry {
    kinds: IndexMap<&'static str, KindDecl>,
}

impl Registry {
    /// An empty registry.
    #[must_use]
    pub fn empty() -> Self {
        Self::default()
    }

    /// The core kinds: `Se Sf R C I TF MTF GY MGY 0 1 lag p_control signal` ([`bondgraph::kinds`]).
    #[must_use]
    pub fn with_core() -> Self {
        let mut r = Self::empty();
        r.add(bondgraph::kinds::KINDS);
        r
    }

    /// Register every kind of `kinds`; a later registration of a name replaces the earlier.
    pub fn add(&mut self, kinds: &[KindDecl]) {
        for k in kinds {
            self.register(*k);
        }
    }

    /// Register one kind.
    pub fn register(&mut self, kind: KindDecl) {
        self.kinds.insert(kind.name, kind);
    }

    /// The kind called `kind`.
    #[must_use]
    pub fn get(&self, kind: &str) -> Option<&KindDecl> {
        self.kinds.get(kind)
    }

    /// All kinds, in registration order.
    pub fn kinds(&self) -> impl Iterator<Item = &KindDecl> {
        self.kinds.values()
    }
}
