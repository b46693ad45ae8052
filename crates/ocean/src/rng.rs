//! PCG-XSH-RR 64/32 (O'Neill 2014, the generator `pcg32` of the PCG family): a 64-bit linear
//! congruential state, multiplier 6364136223846793005, output by an xorshift and a random
//! rotation to 32 bits. Integer arithmetic only (wrapping), so the same seed gives the same
//! numbers on every machine and compiler. Seeding follows the reference `pcg32_srandom_r`
//! with the stream (increment) fixed to 54 (the reference example's).

/// The PCG32 generator (see the module documentation).
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

const MULT: u64 = 6_364_136_223_846_793_005;

impl Pcg32 {
    /// The generator for `seed` (reference seeding: `initstate = seed`, `initseq = 54`).
    #[must_use]
    pub fn new(seed: u64) -> Self {
        let mut r = Self {
            state: 0,
            inc: (54 << 1) | 1,
        };
        let _ = r.next_u32();
        r.state = r.state.wrapping_add(seed);
        let _ = r.next_u32();
        r
    }
    /// The next 32 random bits.
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULT).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }
    /// A uniform number in [0, 1) with 53 random bits (two outputs: high 27, low 26 bits).
    pub fn uniform(&mut self) -> f64 {
        let hi = u64::from(self.next_u32() >> 5);
        let lo = u64::from(self.next_u32() >> 6);
        ((hi << 26) | lo) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp, clippy::panic)]
    use super::*;

    #[test]
    fn matches_the_reference_pcg32_sequence() {
        // pcg32-demo of the reference C implementation: seed 42, sequence 54 prints
        // 0xa15c02b7 0x7b47f409 0xba1d3330 0x83d2f293 0xbfa4784b 0xcbed606e
        let mut r = Pcg32::new(42);
        let got: Vec<u32> = (0..6).map(|_| r.next_u32()).collect();
        assert_eq!(
            got,
            [0xa15c_02b7, 0x7b47_f409, 0xba1d_3330, 0x83d2_f293, 0xbfa4_784b, 0xcbed_606e]
        );
    }

    #[test]
    fn uniforms_lie_in_the_unit_interval_with_mean_one_half() {
        let mut r = Pcg32::new(7);
        let n = 100_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let u = r.uniform();
            assert!((0.0..1.0).contains(&u));
            sum += u;
        }
        // standard error of the mean: 1/sqrt(12 n) ≈ 9e-4
        assert!((sum / f64::from(n) - 0.5).abs() < 4e-3);
    }
}
