//! `bg-sim kinds`: the element kinds a model file can use ([`bg_sim::kinds`]).

use std::process::ExitCode;

use bg_sim::registry;

/// The options of `bg-sim kinds` (its summary is on `Command::Kinds` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// A kind to describe in full (`hydraulics.chamber`).
    pub name: Option<String>,
}

/// `bg-sim kinds`.
pub fn command(a: &Args) -> ExitCode {
    match &a.name {
        None => {
            say!("{}", bg_sim::kinds::list(&registry()).trim_end());
            ExitCode::SUCCESS
        }
        Some(name) => match bg_sim::kinds::report(&registry(), name) {
            Ok(text) => {
                say!("{}", text.trim_end());
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        },
    }
}
