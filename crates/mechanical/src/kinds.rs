//! The mechanical kinds a model loader registers (`mechanical.winch`).

use bondgraph::KindDecl;

/// Every mechanical kind.
pub const KINDS: &[KindDecl] = &[crate::winch::KIND];
