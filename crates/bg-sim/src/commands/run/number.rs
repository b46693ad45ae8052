//! The CSV's numbers: an `f64` written exactly as `format!("{v}")` writes it (the shortest
//! digits that read back to the same value, never an exponent: `0.0000001`, `1e21` as
//! `1000000000000000000000`, `-0`, `NaN`, `inf`), from `zmij`'s shortest digits, which are
//! about five times cheaper than the standard formatter's. The crane's results file is
//! byte-identical either way (tested on random bit patterns and the awkward values).

/// Append `v` to `out` as `{}` would.
pub fn push_f64(out: &mut Vec<u8>, v: f64) {
    if !v.is_finite() || v == 0.0 || short_exact(v) {
        // NaN, ±inf, ±0, and values whose exact decimal expansion is short (where two
        // shortest candidates can tie and the two writers break the tie differently:
        // -1.6758136382377612…e14 is `…776.13` by `{}`, `…776.12` by zmij): the standard
        // writer is the definition
        use std::io::Write;
        let _ = write!(out, "{v}");
        return;
    }
    let mut buf = zmij::Buffer::new();
    let s = buf.format_finite(v).as_bytes();
    // zmij's exponent is `e±d`, `e±dd` or `e±ddd`: its `e` is among the last five bytes (the
    // whole number searched was 6.6 M instructions of memchr a crane CSV)
    if !s[s.len().saturating_sub(5)..].contains(&b'e') {
        // plain decimal notation, and not an integer (those are short exact values): the
        // same text as `{}`
        out.extend_from_slice(s);
        return;
    }
    let (neg, s) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, s),
    };
    // digits and the decimal exponent e of `0.d1d2…dn × 10^e`
    let (mantissa, exp10) = match s.iter().position(|&b| b == b'e' || b == b'E') {
        Some(k) => (&s[..k], parse_exp(&s[k + 1..])),
        None => (s, 0),
    };
    let mut digits = [0u8; 40];
    let mut n = 0;
    let mut point = None;
    for &b in mantissa {
        if b == b'.' {
            point = Some(n);
        } else if n < digits.len() {
            digits[n] = b;
            n += 1;
        }
    }
    let mut int_digits = point.unwrap_or(n) as i32;
    // leading zeros (`0.00123`) and trailing zeros (`1.0`, `100`) carry no digits
    let mut first = 0;
    while first < n && digits[first] == b'0' {
        first += 1;
        int_digits -= 1;
    }
    while n > first && digits[n - 1] == b'0' {
        n -= 1;
    }
    let d = &digits[first..n];
    let e = int_digits + exp10;
    if neg {
        out.push(b'-');
    }
    let len = d.len() as i32;
    if e <= 0 {
        out.extend_from_slice(b"0.");
        out.extend(std::iter::repeat_n(b'0', (-e) as usize));
        out.extend_from_slice(d);
    } else if e < len {
        out.extend_from_slice(&d[..e as usize]);
        out.push(b'.');
        out.extend_from_slice(&d[e as usize..]);
    } else {
        out.extend_from_slice(d);
        out.extend(std::iter::repeat_n(b'0', (e - len) as usize));
    }
}

/// Whether the exact value of `v` (finite, not zero) has at most 18 significant decimal
/// digits, or is an integer: the only values where a shortest representation of ≤ 17
/// digits can be a tie between two candidates. Every other value has one closest shortest
/// representation, which both writers choose.
fn short_exact(v: f64) -> bool {
    let bits = v.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1 << 52) - 1);
    let (m, q) = if exp == 0 {
        (frac, -1074)
    } else {
        (frac | (1 << 52), exp - 1075)
    };
    let tz = m.trailing_zeros() as i32;
    // v = m' · 2^(−k), m' odd: exactly m'·5^k / 10^k, whose digits are those of m'·5^k
    let k = -q - tz;
    if k <= 0 {
        return true;
    }
    if k > 27 {
        // m'·5^k ≥ 5^28 > 10^19: more than 18 digits
        return false;
    }
    let exact = u128::from(m >> tz) * 5u128.pow(k as u32);
    exact < 1_000_000_000_000_000_000
}

fn parse_exp(s: &[u8]) -> i32 {
    let (neg, s) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        Some((b'+', rest)) => (false, rest),
        _ => (false, s),
    };
    let v = s
        .iter()
        .fold(0i32, |a, &b| a * 10 + i32::from(b.wrapping_sub(b'0')));
    if neg {
        -v
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::push_f64;

    fn check(v: f64) {
        let mut out = Vec::new();
        push_f64(&mut out, v);
        assert_eq!(
            String::from_utf8_lossy(&out),
            format!("{v}"),
            "bits {:#x}",
            v.to_bits()
        );
    }

    #[test]
    fn awkward_values_are_written_as_the_standard_writer_writes_them() {
        for v in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.3,
            1e-7,
            1.5e-300,
            5e-324,
            f64::MIN_POSITIVE,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            1e15,
            1e16,
            1e21,
            1e22,
            123_456_789.012_345_68,
            2.299_523e6,
            -80_555.761_08,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            std::f64::consts::PI,
            1.0 / 3.0,
            9_007_199_254_740_993.0,
            f64::from_bits(0xc2e3_0d42_752c_9404), // -167581363823776.12…, a tie
            0.5,
            2.25,
            1e-3,
        ] {
            check(v);
        }
        for k in -330..310 {
            check(10f64.powi(k));
            check(-1.234_567_890_123_456_7 * 10f64.powi(k));
        }
        // binary fractions of every size: the ties
        for k in 0..64 {
            for m in [1u64, 3, 5, 0x1f_ffff_ffff_ffff, 0x12_3456_789a_bcdf] {
                let v = m as f64 / 2f64.powi(k);
                check(v);
                check(v * 1e10 + 0.125);
            }
        }
    }

    #[test]
    fn random_bit_patterns_are_written_as_the_standard_writer_writes_them() {
        // xorshift64*: 200 000 patterns over every exponent, as many "round" values, and as
        // many of the magnitudes a results file holds
        let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = || {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            s.wrapping_mul(0x2545_F491_4F6C_DD1D)
        };
        for _ in 0..200_000 {
            check(f64::from_bits(next()));
            let r = next();
            let digits = (r % 1_000_000) as f64;
            let scale = 10f64.powi((r >> 32) as i32 % 40 - 20);
            check(digits * scale);
            // the values of a results file: any mantissa, magnitudes 1e-12 … 1e12
            let r = next();
            let exp = 1023 - 40 + (r >> 52) % 80;
            check(f64::from_bits(
                (r & ((1 << 52) - 1)) | (exp << 52) | (r & (1 << 63)),
            ));
        }
    }
}
