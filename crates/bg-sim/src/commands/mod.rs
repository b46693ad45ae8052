//! The commands of `bg-sim`, one module each: its options (a `clap::Args` struct) and its
//! body (`command`). What they share: the exit statuses, `--floor` arguments and the
//! interrupt on SIGINT/SIGTERM.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

pub mod bench;
pub mod check;
pub mod compare;
pub mod energy;
pub mod fatigue;
pub mod fit;
pub mod fmu;
pub mod graph;
pub mod json;
pub mod kinds;
pub mod linearize;
pub mod modes;
pub mod optimize;
pub mod plot;
pub mod reduce;
pub mod run;
pub mod sea;
pub mod sensitivity;
pub mod stress;
pub mod sweep;

/// Exit statuses (README, "Exit status").
pub const BAD_INPUT: u8 = 2;
/// The run, a check or the output failed.
pub const FAILED: u8 = 1;

/// `--floor PATTERN=VALUE` arguments, or `None` after printing why one is refused.
pub fn parse_floors(args: &[String]) -> Option<Vec<(String, f64)>> {
    let mut floors = Vec::new();
    for f in args {
        match f
            .split_once('=')
            .map(|(p, v)| (p.trim(), v.trim().parse::<f64>()))
        {
            Some((p, Ok(v))) if !p.is_empty() && v.is_finite() && v >= 0.0 => {
                floors.push((p.to_owned(), v));
            }
            _ => {
                tell!("error: --floor `{f}`: expected PATTERN=VALUE with a finite VALUE ≥ 0\n  hint: --floor 'qb*=1e-3'");
                return None;
            }
        }
    }
    Some(floors)
}

/// SIGINT and SIGTERM set the returned flag, which the run checks after every step: it stops
/// and keeps its rows in `OUT.partial.csv`. A second signal ends the process at once (exit 1),
/// leaving the rows written so far in `OUT.partial.csv`.
pub fn interrupt_on_signals() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        // registration fails only for forbidden signals; without it, the default action stays
        let _ = signal_hook::flag::register_conditional_shutdown(
            sig,
            i32::from(FAILED),
            Arc::clone(&flag),
        );
        let _ = signal_hook::flag::register(sig, Arc::clone(&flag));
    }
    flag
}
