//! The FMI state machines (2.0 and 3.0 co-simulation, without events) an [`Instance`]
//! follows: instantiated → initialisation → stepping → terminated, reset back to the start;
//! a call out of turn is an error with the reason logged.

use super::{Failure, Instance};

/// Where an instance is in the FMI state machines (FMI 2.0 co-simulation and FMI 3.0
/// co-simulation, without events): instantiated → initialisation → stepping → terminated;
/// reset goes back to the start. A call out of turn is an error with the reason logged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// After instantiate or reset: setup, parameters, enter initialisation.
    Instantiated,
    /// Between enter and exit initialisation.
    Initialization,
    /// After exit initialisation: steps.
    Stepping,
    /// After terminate: reset or free only.
    Terminated,
}

impl Phase {
    fn words(self) -> &'static str {
        match self {
            Self::Instantiated => "just instantiated (or reset)",
            Self::Initialization => "in initialisation mode",
            Self::Stepping => "stepping (initialisation done)",
            Self::Terminated => "terminated",
        }
    }
}

impl Instance {
    /// Where the instance is in the FMI state machine.
    #[must_use]
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Refuse `call` unless the instance is in one of `allowed`.
    ///
    /// # Errors
    /// The call out of turn, saying where the instance is and what comes first.
    pub fn require(&self, call: &str, allowed: &[Phase]) -> Result<(), Failure> {
        if allowed.contains(&self.phase) {
            return Ok(());
        }
        let next = match self.phase {
            Phase::Instantiated => "enter initialisation mode first",
            Phase::Initialization => "exit initialisation mode first",
            Phase::Stepping => "this belongs before initialisation: reset the instance first",
            Phase::Terminated => "the instance is terminated: reset it or free it",
        };
        Err(Failure::error(format!(
            "{}: {call} called out of turn: the instance is {}\n  hint: {next} (the FMI state machine)",
            self.file,
            self.phase.words()
        )))
    }

    /// `call` (the setup, or FMI 3's enter with the start time): the start time, only
    /// before initialisation.
    ///
    /// # Errors
    /// Called out of turn.
    pub fn setup_checked(&mut self, call: &str, start_time: f64) -> Result<(), Failure> {
        self.require(call, &[Phase::Instantiated])?;
        self.setup(start_time);
        Ok(())
    }

    /// Enter initialisation mode (once, after instantiation or reset).
    ///
    /// # Errors
    /// Called out of turn.
    pub fn enter_init(&mut self, call: &str) -> Result<(), Failure> {
        self.require(call, &[Phase::Instantiated])?;
        self.phase = Phase::Initialization;
        Ok(())
    }

    /// End of initialisation: the run starts (if it has not).
    ///
    /// # Errors
    /// Called out of turn; the model failing to start (a limit crossed, a state not finite).
    pub fn exit_init(&mut self, call: &str) -> Result<(), Failure> {
        self.require(call, &[Phase::Initialization])?;
        self.running()?;
        self.phase = Phase::Stepping;
        Ok(())
    }

    /// Terminate: after this only reset or free.
    ///
    /// # Errors
    /// Called out of turn (before initialisation ended, or twice).
    pub fn terminate(&mut self, call: &str) -> Result<(), Failure> {
        self.require(call, &[Phase::Stepping])?;
        self.phase = Phase::Terminated;
        Ok(())
    }
}
