//! # bg-hydraulics: valve-controlled cylinder drives as bond-graph components
//!
//! The hydraulic laws of Cibicik & Egeland (2019), sections 2.4 and 4.3 (eqs. 27–31, 78–83),
//! as elements for the [`bondgraph`] core and kinds for model files. A chamber of oil
//! discharging through an orifice to tank, built and run:
//!
//! ```
//! use bondgraph::*;
//! use bg_hydraulics::{Chamber, Orifice};
//! let mut g = BondGraph::new();
//! g.add("oil", Chamber::fixed(1e-3, 1.5e9, 10e6)?)?;      // 1 l at 10 MPa
//! g.add("line", ZeroJunction)?;
//! g.add("drain", Orifice::new(1e-7, 1.0, 1e5)?)?;          // α = 1e-7 m³/(s·√Pa)
//! g.add("tank", EffortSource::new(0.0))?;
//! for (a, b) in [("line", "oil"), ("line", "drain"), ("drain", "tank")] {
//!     g.connect_names(a, b)?; // the orifice's ports a, b in order
//! }
//! let mut eqs = StateEquations::new(assign_causality(g)?)?;
//! let x0 = eqs.initial_state();
//! let settings = Settings { t_end: 0.2, ..Settings::default() };
//! let run = simulate(&mut eqs, &x0, &settings, &[], vec![]);
//! assert!(run.error.is_none());
//! assert!(run.x_final[0] < 1e6); // drained below 1 MPa
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Elements (one file each: law, causality, tests)
//! - [`Chamber`] (`hydraulics.chamber`): C with a pressure state, V = A(l⁰ ± s) (eq. 28).
//! - [`Piston`] (`hydraulics.piston`): the TF pair A_p, A_r (eqs. 80–81) and the stroke.
//! - [`EndStop`] (`hydraulics.end_stop`): stiff spring–damper past the stroke ends.
//! - [`Leakage`] (`hydraulics.leakage`, `hydraulics.tank_leakage`): laminar R (eq. 82).
//! - [`Laminar`] (`hydraulics.laminar`): a pipe's laminar resistance (Hagen–Poiseuille).
//! - [`Orifice`] (`hydraulics.orifice`) and [`Valve`] (`hydraulics.valve`): eqs. 29–31 with
//!   the square root regularised by [`reg_root`].
//! - [`Machine`] (`hydraulics.pump`, `hydraulics.motor`): displacement machine, Q = D·ω,
//!   T = D·Δp with leakage and friction losses; a pump may run at a set `speed`.
//! - [`Friction`] (`hydraulics.friction`): regularised Coulomb + Stribeck + viscous
//!   ([`FrictionLaw`], also the machines' friction torque).
//! - [`Accumulator`] (`hydraulics.accumulator`): gas-charged C, oil-volume state, polytropic
//!   gas law, stiff oil below the precharge.
//! - [`Line`] (`hydraulics.line`): N lumped C–R–I segments of a pipe or hose
//!   (Hagen–Poiseuille, inertance, wall compliance).
//! - [`Tank`] (`hydraulics.tank`): constant pressure, counts the volume it receives.
//! - [`fluid`]: the chamber's options, entrained air (β_eff(p)) and cavitation.
//!
//! The spool's P-controller (eq. 83) and first-order lag are the core's `p_control` and
//! `lag`; they read the cylinder length `<cylinder>_piston.l`.
//!
//! ## Valves (any supply: every port is hydraulic; `docs/hydraulics.md`, "Valves")
//! Each opening passes oil as an orifice, `α·x·regRoot(Δp)`, with a laminar leak; every valve
//! conserves volume and only dissipates.
//! - Pressure-operated, on the shared law of [`PressureValve`] with the C¹ opening [`ramp`]:
//!   [`ReliefValve`] (`hydraulics.relief_valve`, optional poppet lag), [`CheckValve`]
//!   (`hydraulics.check_valve`), [`PilotCheckValve`] (`hydraulics.pilot_check_valve`),
//!   [`CounterbalanceValve`] (`hydraulics.counterbalance_valve`), [`SequenceValve`]
//!   (`hydraulics.sequence_valve`), [`PressureReducingValve`]
//!   (`hydraulics.pressure_reducing_valve`).
//! - Spool-operated: [`DirectionalValve`] (`hydraulics.directional_valve`: 4/3, ports P, T,
//!   A, B, [`Centre`] closed/open/tandem/float, overlap/underlap), [`Valve22`]
//!   (`hydraulics.valve_2_2`), [`Valve32`] (`hydraulics.valve_3_2`).
//! - [`FlowControlValve`] (`hydraulics.flow_control_valve`): pressure-compensated.
//!
//! ## Load sensing (`docs/hydraulics.md`, "Load sensing")
//! - [`LsPump`] (`hydraulics.ls_pump`): variable pump with its swash plate a state, LS
//!   margin, pressure cut-off, optional torque limiter ([`LsController`]).
//! - [`ShuttleValve`] (`hydraulics.shuttle_valve`): the higher of two pressures passes.
//! - `hydraulics.ls_line` ([`ls_line`]): the LS signal volume with its bleed to tank.
//! - [`LsSection`] (`hydraulics.ls_section`): a proportional 4/3 section with an LS port and
//!   a pre- or post-compensator ([`Compensator`]).
//!
//! ## The cylinder as one component
//! [`Cylinder`] (`hydraulics.cylinder`) assembles chambers, piston, leakage, valve and end
//! stop; [`Cylinder::composite`] for model files, [`Cylinder::add_to`] for a [`BondGraph`].
//! [`hold_pressures`] is the static initialisation rule. [`buckling`]: the rod's Euler/Johnson
//! load ([`buckling_load`], [`Fixity`]) and the check member [`RodCheck`].
//!
//! ## Model files
//! [`KINDS`] lists every kind, each a [`bondgraph::KindDecl`] declared beside its law;
//! `docs/hydraulics.md` documents each kind's law, parameters and units.
//!
//! [`BondGraph`]: bondgraph::BondGraph

pub mod accumulator;
pub mod buckling;
pub mod chamber;
pub mod check_valve;
pub mod counterbalance_valve;
pub mod cylinder;
pub mod directional_valve;
pub mod end_stop;
pub mod flow_control_valve;
pub mod fluid;
pub mod friction;
pub mod kinds;
pub mod laminar;
pub mod leakage;
pub mod line;
pub mod ls_line;
pub mod ls_pump;
pub mod ls_section;
pub mod machine;
pub mod orifice;
pub mod pilot_check_valve;
pub mod piston;
pub mod pressure_reducing_valve;
pub mod pressure_valve;
pub mod ramp;
pub mod relief_valve;
pub mod sequence_valve;
pub mod shuttle_valve;
pub mod tank;
pub mod valve;
pub mod valve_2_2;
pub mod valve_3_2;

pub use accumulator::Accumulator;
pub use buckling::{buckling_load, Fixity, Rod, RodCheck};
pub use chamber::{Chamber, Side};
pub use check_valve::CheckValve;
pub use counterbalance_valve::CounterbalanceValve;
pub use cylinder::{
    hold_pressures, Cylinder, CylinderPorts, EndStopSpec, InitialPressures, ValveSpec,
};
pub use directional_valve::{Centre, DirectionalValve};
pub use end_stop::EndStop;
pub use flow_control_valve::FlowControlValve;
pub use fluid::{Fluid, FluidOptions};
pub use friction::{Friction, FrictionLaw};
pub use kinds::KINDS;
pub use laminar::{pipe_resistance, Laminar};
pub use leakage::Leakage;
pub use line::{Line, LineSpec, Wall};
pub use ls_pump::{LsController, LsPump};
pub use ls_section::{Compensator, LsSection};
pub use machine::{Machine, Role};
pub use orifice::{alpha, reg_root, reg_root_derivative, Orifice};
pub use pilot_check_valve::PilotCheckValve;
pub use piston::Piston;
pub use pressure_reducing_valve::PressureReducingValve;
pub use pressure_valve::{Opening, PressureValve};
pub use ramp::ramp;
pub use relief_valve::ReliefValve;
pub use sequence_valve::SequenceValve;
pub use shuttle_valve::{smooth_max, ShuttleValve};
pub use tank::Tank;
pub use valve::Valve;
pub use valve_2_2::Valve22;
pub use valve_3_2::Valve32;
