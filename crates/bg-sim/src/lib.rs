//! The `bg-sim` front end as a library: the registry of every element kind this build
//! knows, shared by the CLI and the workspace tests, the figures of a results CSV
//! ([`plot`]), the speed–accuracy measurements of `bench` ([`bench`](mod@bench)), the scene search
//! of `reduce` ([`reduce`]) and its reduction by activity ([`simplify`]), the time-scale report of `bg-sim modes` ([`modes`]) and
//! sweeps: many runs of one model in parallel, one summary row each ([`sweep`]), and the
//! drawing of a model's bond graph (`bg-sim graph`, [`graph`](mod@graph)), and the progress
//! bar of `bg-sim run` ([`progress`]), and the energy audit's tables and figures of
//! `bg-sim energy` ([`energy`](mod@energy)). No physics lives here.

use bg_model::Registry;

pub mod bench;
pub mod energy;
pub mod fit;
pub mod graph;
pub mod kinds;
pub mod modes;
pub mod plot;
pub mod progress;
pub mod reduce;
pub mod simplify;
pub mod sweep;

/// Every element kind this build knows: the core kinds plus the domain crates'.
#[must_use]
pub fn registry() -> Registry {
    let mut r = Registry::with_core();
    r.add(bg_hydraulics::KINDS);
    r.add(bg_manipulator::KINDS);
    r.add(bg_mechanical::KINDS);
    r
}
