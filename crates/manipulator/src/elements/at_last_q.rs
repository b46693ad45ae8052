//! [`AtLastQ`]: a value computed at an argument — a configuration q, or a state (p, q) —
//! and kept until the argument changes.
//!
//! Within one evaluation every stage of an element, and its partials, see the same argument,
//! so the element computes once and the other stages reuse the result. The comparison is bit
//! for bit (`-0.0` and `0.0` differ; a NaN matches only the same NaN), and the buffers — the
//! argument's copy and the value — are allocated once, at construction: the value is
//! updated in place.

/// A value of type `T` and the argument it was computed at.
#[derive(Clone, Debug)]
pub(crate) struct AtLastQ<T> {
    q: Vec<f64>,
    valid: bool,
    value: T,
}

impl<T> AtLastQ<T> {
    /// Room for arguments of length n, and the buffers of the value (`value`, whose contents
    /// are not used before the first [`get_or_update`](Self::get_or_update)).
    pub(crate) fn new(n: usize, value: T) -> Self {
        Self {
            q: vec![0.0; n],
            valid: false,
            value,
        }
    }

    /// The value at `q`, and `q` (the kept copy). Unless `q` is, bit for bit, the argument of
    /// the last update, `compute(q, value)` first updates the value in place.
    pub(crate) fn get_or_update(
        &mut self,
        q: &[f64],
        compute: impl FnOnce(&[f64], &mut T),
    ) -> (&[f64], &T) {
        if !self.is_at(q) {
            // a failed `compute` (a panic) leaves the value invalid
            self.valid = false;
            self.q.clear();
            self.q.extend_from_slice(q);
            compute(&self.q, &mut self.value);
            self.valid = true;
        }
        (&self.q, &self.value)
    }

    /// Whether the value is the one at `q`.
    pub(crate) fn is_at(&self, q: &[f64]) -> bool {
        self.valid && same_bits(&self.q, q)
    }
}

/// Whether `a` and `b` hold the same numbers bit for bit (so −0 ≠ +0 and a NaN equals
/// itself): the test of every per-configuration cache of the arm.
pub(crate) fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn computes_once_per_argument_bit_for_bit() {
        let mut calls = 0;
        // the value: the bits of the sum
        let mut sum = AtLastQ::new(2, 0_u64);
        let mut at = |q: &[f64]| {
            *sum.get_or_update(q, |q, s| {
                calls += 1;
                *s = q.iter().sum::<f64>().to_bits();
            })
            .1
        };
        assert_eq!(at(&[1.0, 2.0]), 3.0_f64.to_bits());
        assert_eq!(at(&[1.0, 2.0]), 3.0_f64.to_bits());
        assert_eq!(at(&[1.0, -0.0]), 1.0_f64.to_bits());
        assert_eq!(at(&[1.0, 0.0]), 1.0_f64.to_bits());
        assert_eq!(at(&[1.0, 0.0]), 1.0_f64.to_bits());
        assert_eq!(calls, 3);
        assert!(sum.is_at(&[1.0, 0.0]) && !sum.is_at(&[1.0, -0.0]));
        assert_eq!(
            sum.get_or_update(&[1.0, 0.0], |_, _| unreachable!()).0,
            &[1.0, 0.0]
        );
    }

    #[test]
    fn a_nan_matches_only_its_own_bits() {
        let mut v = AtLastQ::new(1, 0_u32);
        for _ in 0..2 {
            v.get_or_update(&[f64::NAN], |_, n| *n += 1);
        }
        assert_eq!(*v.get_or_update(&[-f64::NAN], |_, n| *n += 1).1, 2);
    }
}
