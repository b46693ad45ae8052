//! `bg-sim fmu`: a model as an FMI 2.0 (default) or 3.0 co-simulation FMU ([`bg_fmu`]):
//! `modelDescription.xml`, the engine library (`cargo build -p bg-fmu`), and the model with
//! its data and tables in `resources/` (docs/fmu.md).

use std::path::PathBuf;
use std::process::ExitCode;

use bg_fmu::{ExportError, FmiVersion};

use super::{BAD_INPUT, FAILED};

/// The options of `bg-sim fmu` (its summary is on `Command::Fmu` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The model file.
    pub model: PathBuf,
    /// The FMU to write (`model.fmu`).
    #[arg(short = 'o', long = "output", value_name = "FILE.fmu")]
    pub output: PathBuf,
    /// FMI version: 2 (FMI 2.0) or 3 (FMI 3.0).
    #[arg(long, default_value_t = 2, value_name = "2|3")]
    pub fmi: u8,
    /// Override a value of the model file (repeatable); the FMU carries the changed file.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The engine library (`libbg_fmu.so`); default: next to this executable.
    #[arg(long, value_name = "PATH")]
    pub library: Option<PathBuf>,
}

/// The library next to the running executable (`target/{debug,release}/libbg_fmu.so`).
fn library_beside_exe() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let lib = exe.parent()?.join("libbg_fmu.so");
    lib.is_file().then_some(lib)
}

/// `bg-sim fmu`.
pub fn command(a: &Args) -> ExitCode {
    let version = match a.fmi {
        2 => FmiVersion::V2,
        3 => FmiVersion::V3,
        v => {
            tell!("error: --fmi {v}: FMI 2.0 and 3.0 are offered\n  hint: --fmi 2 or --fmi 3");
            return ExitCode::from(BAD_INPUT);
        }
    };
    let library = match &a.library {
        Some(l) => l.clone(),
        None => match library_beside_exe() {
            Some(l) => l,
            None => {
                tell!("error: the FMU's engine library (libbg_fmu.so) is not next to bg-sim\n  hint: build it with `cargo build -p bg-fmu` (with --release for a release bg-sim), or name it with --library PATH");
                return ExitCode::from(BAD_INPUT);
            }
        },
    };
    if !library.is_file() {
        tell!(
            "error: {}: no such library\n  hint: build it with `cargo build -p bg-fmu`",
            library.display()
        );
        return ExitCode::from(BAD_INPUT);
    }
    match bg_fmu::export(&a.model, &a.set, version, &library, &a.output) {
        Ok(x) => {
            let d = &x.description;
            let count = |f: fn(&bg_fmu::description::Role) -> bool| {
                d.variables.iter().filter(|v| f(&v.role)).count()
            };
            use bg_fmu::description::Role;
            say!(
                "{}: FMI {} co-simulation FMU `{}` ({} inputs, {} outputs, {} parameters; {} files)",
                a.output.display(),
                if version == FmiVersion::V2 { "2.0" } else { "3.0" },
                x.model_identifier,
                count(|r| matches!(r, Role::Input(_))),
                count(|r| matches!(r, Role::Output(_))),
                count(|r| matches!(r, Role::Parameter(_))),
                x.entries.len()
            );
            ExitCode::SUCCESS
        }
        Err(ExportError::Model(e)) => {
            tell!("error: {e}");
            ExitCode::from(BAD_INPUT)
        }
        Err(ExportError::File(m)) => {
            tell!("error: {m}");
            ExitCode::from(BAD_INPUT)
        }
        Err(ExportError::Output(m)) => {
            tell!("error: {m}");
            ExitCode::from(FAILED)
        }
    }
}
