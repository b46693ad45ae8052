//! The knuckle boom (docs/knuckle-boom.md), shared by the integration tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::f64::consts::PI;

use bg_manipulator::{LinearActuator, Link, LumpedMass, Pin, PlanarArm};

pub const G: f64 = 9.81;
pub const M3: f64 = 5000.0;
pub const M_P: f64 = 235.0;
pub const M_B: f64 = 713.0;

/// Link 1 and 2 of docs/knuckle-boom.md with `modes` sine modes each, and the payload pendulum.
pub fn crane_links(modes: u32) -> Vec<Link> {
    let beam = |l: f64| {
        Link::beam(l, 210e9, 7850.0, 0.0264, 5.89e-4)
            .unwrap()
            .with_sine_modes(modes)
            .unwrap()
    };
    vec![beam(10.0), beam(8.0), Link::pendulum(6.0, M3).unwrap()]
}

pub fn crane(modes: u32) -> PlanarArm {
    PlanarArm::new(crane_links(modes), G).unwrap()
}

/// Cylinder 1 from the base pin B to H1,1; cylinder 2 from H1,2 to H2,1.
pub fn cylinders() -> Vec<LinearActuator> {
    let b3 = PI / 3.0;
    vec![
        LinearActuator::new(
            Pin::ground(3.0 * b3.cos(), -3.0 * b3.sin()),
            Pin::on_link(0, 4.0),
        ),
        LinearActuator::new(Pin::on_link(0, 6.0), Pin::on_link(1, 3.0)),
    ]
}

/// Piston 1 at H1,1, barrel 2 at H1,2, piston 2 at H2,1.
pub fn lumped_masses() -> Vec<LumpedMass> {
    vec![
        LumpedMass {
            pin: Pin::on_link(0, 4.0),
            mass: M_P,
        },
        LumpedMass {
            pin: Pin::on_link(0, 6.0),
            mass: M_B,
        },
        LumpedMass {
            pin: Pin::on_link(1, 3.0),
            mass: M_P,
        },
    ]
}

/// The initial pose q1 = 0, q2 = −2π/3, q3 = π/6 with `n_modal` zero modal coordinates.
pub fn initial_pose(n_modal: usize) -> Vec<f64> {
    let mut q = vec![0.0, -2.0 * PI / 3.0, PI / 6.0];
    q.extend(std::iter::repeat_n(0.0, n_modal));
    q
}

/// A small deterministic pseudo-random generator (xorshift), values in [lo, hi).
pub struct Rng(u64);
impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed.max(1))
    }
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    /// A random configuration: angles in [−π, π), modal coordinates up to ±`amp` m.
    pub fn q(&mut self, arm: &PlanarArm, amp: f64) -> Vec<f64> {
        (0..arm.n())
            .map(|k| {
                if k < arm.n_links() {
                    self.uniform(-PI, PI)
                } else {
                    self.uniform(-amp, amp)
                }
            })
            .collect()
    }
    pub fn vec(&mut self, n: usize, scale: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(-scale, scale)).collect()
    }
}

/// Newton's method with a central-difference Jacobian for f(x) = 0 (small dense systems).
pub fn newton(mut x: Vec<f64>, f: impl Fn(&[f64]) -> Vec<f64>, scale: &[f64]) -> Vec<f64> {
    let n = x.len();
    for _ in 0..50 {
        let r = f(&x);
        let mut j = nalgebra::DMatrix::zeros(n, n);
        for k in 0..n {
            let h = 1e-6 * scale[k];
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[k] += h;
            xm[k] -= h;
            let (fp, fm) = (f(&xp), f(&xm));
            for i in 0..n {
                j[(i, k)] = (fp[i] - fm[i]) / (2.0 * h);
            }
        }
        let dx = j.lu().solve(&nalgebra::DVector::from_vec(r)).unwrap();
        let mut small = true;
        for k in 0..n {
            x[k] -= dx[k];
            small &= dx[k].abs() <= 1e-14 * scale[k].max(x[k].abs());
        }
        if small {
            break;
        }
    }
    x
}

/// The static cylinder forces of the rigid crane: the first two rows of τ_b F + G = 0.
pub fn static_forces(arm: &PlanarArm, q: &[f64]) -> [f64; 2] {
    let pose = arm.pose(q);
    let tau = arm.actuator_jacobian(&pose, &cylinders());
    let g = arm.kinematics(q).gravity_forces();
    let a = nalgebra::Matrix2::new(tau[(0, 0)], tau[(0, 1)], tau[(1, 0)], tau[(1, 1)]);
    let f = a.lu().solve(&nalgebra::Vector2::new(-g[0], -g[1])).unwrap();
    [f.x, f.y]
}
