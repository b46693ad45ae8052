//! # bg-manipulator: planar flexible manipulators as bond-graph multiport fields
//!
//! Sections 2–5 of Cibicik, Pedersen & Egeland, *Dynamics of luffing motion of a flexible
//! knuckle boom crane actuated by hydraulic cylinders* (Mech. Mach. Theory 2019), with the
//! conventions of `docs/knuckle-boom.md`; `docs/manipulator.md` gives the
//! formulation with the paper's equation numbers.
//!
//! ## Screw algebra (section 2)
//! [`screw`]: twists, wrenches, joint lines, the transformations `U`, `R̄`, `V`
//! ([`ReferenceTransform`], [`CoordinateTransform`], [`ScrewTransform`]) and `Π`
//! ([`screw::interchange`]), planar motion embedded in 6-D as in the paper.
//!
//! ## The arm (section 3.1)
//! [`Link`]s (rigid, Euler–Bernoulli beams with assumed [`ModeShape`]s — [`SineMode`] by
//! default —, point masses, the payload pendulum) joined by [`RevoluteJoint`]s with
//! chord-to-chord angles form a [`PlanarArm`]; [`PlanarArm::pose`] gives its [`Pose`]
//! (or [`PlanarArm::pose_in`], into reusable [`Frames`]) and [`Projection`] the projection
//! matrices (eqs. 24, 38, 73). Each link's [`ShapeIntegrals`] — the Gram matrices of its
//! station features, in closed form for sine modes, else by [`GaussLegendre`] quadrature —
//! are computed once, when the arm is built.
//!
//! ## Dynamics (section 3.2)
//! [`PlanarArm::kinematics`] → [`ArmKinematics`]: the mass matrix
//! ([`ArmKinematics::mass_matrix`], eq. 42), `E = ∂T/∂q` ([`ArmKinematics::kinetic_forces`],
//! eq. 44), gravity ([`ArmKinematics::gravity_forces`], eqs. 45–48), the accelerations, each
//! a contraction of the shape integrals, O(modes²) per link, with `_into` forms that do not
//! allocate; the stiffness ([`PlanarArm::stiffness_matrix`], eq. 51). [`reference`](mod@reference) keeps
//! the per-station quadrature sums as the tests' reference.
//!
//! ## Actuators and lumped masses (sections 3.3, 4.2)
//! [`LinearActuator`] between [`Pin`]s: length from the deformed pins and `τ_b = ∂l/∂q`
//! ([`PlanarArm::actuator_jacobian`], eqs. 52–69); [`LumpedMass`] and `J_c`
//! ([`PlanarArm::lumped_mass_jacobian`], eqs. 70–77).
//!
//! ## Reaction forces (section 5)
//! [`ArmKinematics::reactions`] (eqs. 84–98) with [`PointLoad`]s.
//!
//! ## Beyond the paper's beam
//! [`geometric_stiffening`]: a link option keeping the second-order axial shortening of the
//! bent link in the positions of its points, pins and chord end (axial-force stiffening),
//! with its precomputed [`ShorteningIntegrals`]; [`CantileverMode`]s for the last link.
//!
//! ## Bond-graph elements (section 4)
//! [`elements`]: the I-field ([`ArmInertia`]), C-field ([`ArmCompliance`]), R-field
//! ([`ArmDamping`]), the MTFs to the cylinders ([`ActuatorTransformer`]) and to the lumped
//! masses ([`LumpedMassTransformer`]), the lumped masses themselves, and the reaction-force
//! block ([`ArmReactions`]). [`ArmScene`] wires them into a graph; [`KINDS`] offers the
//! scene to model files as the composite kind `manipulator.planar_arm`.

// Dependencies run one way, down this list: a module uses only modules of its own group
// and of the groups above it.

// Screw algebra (section 2)
pub mod screw;

// The arm (section 3.1)
pub mod arm;
pub mod base;
pub mod joint;
pub mod link;
pub mod mode_shape;
pub mod pin;
pub mod projection;
pub mod quadrature;
pub mod shape_integrals;

// Beyond the paper's beam
pub mod geometric_stiffening;

// Dynamics (section 3.2)
mod cholesky;
pub mod gravity;
pub mod kinematics;
pub mod kinetic_forces;
pub mod mass_matrix;
pub mod stiffness;

// Actuators and lumped masses (sections 3.3, 4.2)
pub mod actuator;
pub mod lumped_mass;

// Second derivatives (for the exact Jacobian), reaction forces (section 5)
pub mod hessians;
pub mod reactions;

// The per-station reference of the tests
pub mod reference;

// Stress recovery: section forces, modal moment, cross-sections (docs/stress.md)
pub mod stress;

// Bond-graph elements (section 4), the scene, the kinds
pub mod elements;
pub mod kinds;
pub mod scene;

pub use actuator::LinearActuator;
pub use arm::{Frames, PlanarArm, Pose, Station};
pub use base::{Base, BaseState};
pub use elements::{
    lumped_masses, ActuatorTransformer, ArmCompliance, ArmDamping, ArmInertia, ArmReactions,
    LumpedGravity, LumpedMassTransformer,
};
pub use geometric_stiffening::ShorteningIntegrals;
pub use joint::RevoluteJoint;
pub use kinds::KINDS;
pub use kinematics::ArmKinematics;
pub use link::{Link, PointMass, Profile};
pub use lumped_mass::LumpedMass;
pub use mode_shape::{CantileverMode, ModeShape, SineMode};
pub use pin::{Pin, PinPoint};
pub use projection::Projection;
pub use quadrature::GaussLegendre;
pub use reactions::PointLoad;
pub use scene::{ArmScene, LumpedMassModel};
pub use screw::{CoordinateTransform, ReferenceTransform, ScrewTransform};
pub use shape_integrals::ShapeIntegrals;
