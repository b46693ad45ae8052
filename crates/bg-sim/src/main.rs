//! `bg-sim`: run and check bond-graph model files. No physics lives here: the CLI loads a
//! model through `bg-model`, runs it through `bondgraph`, and writes the results.
//!
//! This file is the table of contents: every command with its one-line summary (the help of
//! `bg-sim --help`) and the module of [`commands`] that holds its options and its body.
//! Reports go through `say!` and `tell!` ([`report`]), which never panic.

#[macro_use]
mod report;
mod commands;

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use commands::fatigue;
use commands::sensitivity;
use commands::{
    bench, check, compare, energy, fmu, graph, kinds, linearize, modes, plot, reduce, run, sea,
    stress, sweep, FAILED,
};
use commands::{fit, optimize};

#[derive(Parser)]
#[command(
    name = "bg-sim",
    version,
    about = "Simulate port-based bond graphs described in TOML model files"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a model and write its results as CSV.
    Run(run::Args),
    /// Run a model many times over a grid or a Latin-hypercube sample of values, in
    /// parallel, and write one summary row per run (docs/sweeps.md). Started again on the
    /// same folder, it skips the runs already done.
    Sweep(sweep::Args),
    /// Draw one column of a sweep's summary over two swept parameters as filled contours
    /// (PNG); runs without a value are crosses.
    SweepPlot(sweep::PlotArgs),
    /// Check a model: list elements, bonds with causal strokes, states and problems.
    Check(check::Args),
    /// Draw a model's bond graph as SVG or PNG (or Graphviz DOT): element symbols, half-arrows,
    /// causal strokes, signals; composites as one box each unless --expand (docs/graph.md).
    Graph(graph::Args),
    /// List the element kinds a model file can use, or describe one: its ports, parameters
    /// (units, defaults, ranges), states and published signals.
    Kinds(kinds::Args),
    /// The model's time scales: linearise at the initial state (or at time T of a run) and
    /// list every eigenvalue as frequency, damping ratio and time constant with the states
    /// that take part in it, the stiffness ratio and what it means for the solver.
    Modes(modes::Args),
    /// The linear model (A, B, C, D, exact) for named inputs and outputs at the initial state
    /// or at time T of a run, its poles and DC gains; with --bode IN:OUT the frequency
    /// response of one pair (CSV/JSON data, a PNG figure with --plot).
    Linearize(linearize::Args),
    /// Forward sensitivities ∂y/∂p of the [outputs] columns to chosen parameters in one run
    /// (exact Jacobian, staggered with Radau): the time series (CSV), a ranking of normalised
    /// sensitivities, its figure (docs/sensitivity.md).
    Sensitivity(sensitivity::Args),
    /// Measure the speed–accuracy trade: every solver at every rtol against a reference
    /// (wall time, steps, rhs evaluations, the worst scaled error of the scored columns).
    Bench(bench::Args),
    /// Where the energy goes: run a model with its energy audit and list, per composite (or
    /// element, --expand), the energy supplied, stored, dissipated and its activity ∫|P| dt,
    /// the balance and the efficiency; --plot draws it (docs/energy.md).
    Energy(energy::Args),
    /// Find the cheapest scene of the model's `[scene]` switches whose scaled error against
    /// the richest scene stays within --tol on the named columns.
    Reduce(reduce::Args),
    /// Compare a results CSV with a reference CSV, column by column, with the scaled error
    /// of `bench` (|run − reference| / max(range, |mean|, quantity floor)).
    Compare(compare::Args),
    /// Draw a model's `[[plot]]` figures from a results CSV (--model), or a quick look at
    /// some of its columns, one panel each (--columns), as PNG and/or SVG.
    Plot(plot::Args),
    /// Export the model as an FMI 2.0 (or --fmi 3) co-simulation FMU: the model and its data
    /// in resources/, the engine library (`cargo build -p bg-fmu`) in binaries/ (docs/fmu.md).
    Fmu(fmu::Args),
    /// Stresses along the arm's flexible links over a run: envelopes of N, V, M and the
    /// outer-fibre σ (max and min at every section, with their times), the hot spot and its
    /// history, the cylinders' peak pressures and forces (docs/stress.md); --fatigue CURVE
    /// also the hot spots' rainflow count and Miner damage.
    Stress(stress::Args),
    /// Rainflow-count a column of a results CSV (ASTM E1049-85) and its Palmgren–Miner
    /// damage on an S–N curve (EN 1993-1-9, DNV-RP-C203 presets or explicit).
    Fatigue(fatigue::Args),
    /// An irregular sea state (JONSWAP or Pierson–Moskowitz) as a CSV time series: the wave
    /// elevation and, with --rao, the vessel's heave, sway and roll at a point; --plot draws
    /// the record and its spectrum against the target (docs/sea-states.md).
    Sea(sea::Args),
    /// Fit parameters to measured data (weighted least squares, bounded Levenberg–Marquardt):
    /// estimates, standard errors, 95 % intervals, correlations, warnings (docs/fit.md).
    Fit(fit::Args),
    /// Minimise a sweep metric subject to constraints on others over bounded parameters, by a
    /// particle swarm (or Nelder–Mead) whose runs go in parallel (docs/fit.md).
    Optimize(optimize::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // For these commands the report on stdout is the product: losing it is a failure.
    let stdout_is_product = matches!(
        cli.command,
        Command::Kinds { .. }
            | Command::Check { .. }
            | Command::Compare { .. }
            | Command::Modes { .. }
            | Command::Linearize { .. }
            | Command::Energy { .. }
            | Command::Stress { .. }
    );
    let code = dispatch(cli.command);
    let lost = report::STDOUT_ERROR.lock().ok().and_then(|e| *e);
    match lost {
        // the reader went away (`| head`): what it read is what it wanted
        None | Some(std::io::ErrorKind::BrokenPipe) => code,
        Some(kind) => {
            tell!("warning: the report on stdout is incomplete: {kind}");
            if stdout_is_product && code == ExitCode::SUCCESS {
                ExitCode::from(FAILED)
            } else {
                code
            }
        }
    }
}

fn dispatch(command: Command) -> ExitCode {
    match command {
        Command::Run(a) => run::command(a),
        Command::Sweep(a) => sweep::command(a),
        Command::SweepPlot(a) => sweep::plot_command(&a),
        Command::Check(a) => check::command(&a),
        Command::Graph(a) => graph::command(a),
        Command::Kinds(a) => kinds::command(&a),
        Command::Modes(a) => modes::command(&a),
        Command::Linearize(a) => linearize::command(&a),
        Command::Sensitivity(a) => sensitivity::command(&a),
        Command::Bench(a) => bench::command(a),
        Command::Energy(a) => energy::command(&a),
        Command::Reduce(a) => reduce::command(a),
        Command::Compare(a) => compare::command(&a),
        Command::Plot(a) => plot::command(&a),
        Command::Fmu(a) => fmu::command(&a),
        Command::Stress(a) => stress::command(&a),
        Command::Fatigue(a) => fatigue::command(&a),
        Command::Sea(a) => sea::command(&a),
        Command::Fit(a) => fit::command(a),
        Command::Optimize(a) => optimize::command(&a),
    }
}
