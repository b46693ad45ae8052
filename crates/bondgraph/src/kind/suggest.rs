//! "Did you mean …?": the one rule for near misses, used for kinds, parameters, signals and
//! columns alike.

/// Whether `a` looks like a misspelling of `b`: the same ignoring case, one a prefix of the
/// other, or at most one edit (insertion, deletion, substitution) apart.
#[must_use]
pub fn similar(a: &str, b: &str) -> bool {
    if a.eq_ignore_ascii_case(b) || (a.len() > 1 && b.starts_with(a)) || a.starts_with(b) {
        return true;
    }
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    if a.len().abs_diff(b.len()) > 1 {
        return false;
    }
    // Levenshtein distance ≤ 1, one row at a time
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()] <= 1
}

/// The first of `candidates` that `name` looks like a misspelling of.
pub fn suggest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .into_iter()
        .find(|c| *c != name && similar(name, c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_misses_and_far_ones() {
        assert!(similar("beta", "Beta"));
        assert!(similar("bta", "beta"));
        assert!(similar("betaa", "beta"));
        assert!(similar("p_t", "p_tr"));
        assert!(!similar("alpha", "beta"));
        assert!(!similar("x", "xyz_long"));
        assert_eq!(suggest("dampng", ["mass", "damping"]), Some("damping"));
        assert_eq!(suggest("zzz", ["mass", "damping"]), None);
    }
}
