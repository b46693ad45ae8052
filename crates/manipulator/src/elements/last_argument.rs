//! [`LastArgument`]: the argument (state or configuration) of an element's last computation.
//!
//! Within one evaluation every stage of an element, and its derivatives, see the same state,
//! so the element computes once and the others reuse the result. The comparison is bit for
//! bit; the buffer is allocated once, at construction.

/// The argument of the last computation.
#[derive(Clone, Debug)]
pub(crate) struct LastArgument {
    x: Vec<f64>,
    valid: bool,
}

impl LastArgument {
    /// Room for arguments of length n; nothing remembered yet.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            x: vec![0.0; n],
            valid: false,
        }
    }

    /// Whether `x` is the remembered argument. If not, `x` is remembered (and the caller
    /// recomputes).
    pub(crate) fn is_same(&mut self, x: &[f64]) -> bool {
        if self.valid
            && self.x.len() == x.len()
            && self
                .x
                .iter()
                .zip(x)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        {
            return true;
        }
        self.x.clear();
        self.x.extend_from_slice(x);
        self.valid = true;
        false
    }

    /// The remembered argument.
    pub(crate) fn get(&self) -> &[f64] {
        &self.x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remembers_the_last_argument_bit_for_bit() {
        let mut a = LastArgument::new(2);
        assert!(!a.is_same(&[1.0, 2.0]));
        assert!(a.is_same(&[1.0, 2.0]));
        assert!(!a.is_same(&[1.0, -0.0]));
        assert!(!a.is_same(&[1.0, 0.0]));
        assert_eq!(a.get(), &[1.0, 0.0]);
    }
}
