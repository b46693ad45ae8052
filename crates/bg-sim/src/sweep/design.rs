//! The runs of a spec: a full grid or a seeded Latin-hypercube sample ([`points`]), and
//! each run's identity ([`Point::id`]).

use super::spec::{run_count, Design, Spec, Value, Values};

/// One run of a sweep: its position and its values.
#[derive(Clone, Debug)]
pub struct Point {
    /// 0-based position in the design.
    pub index: usize,
    /// `--set` path and value, one per swept parameter.
    pub values: Vec<(String, Value)>,
}

impl Point {
    /// The run's identity: a hash of its paths and values (16 hex digits), the same across
    /// processes and machines, so a resumed sweep recognises the runs it already did.
    #[must_use]
    pub fn id(&self) -> String {
        // FNV-1a, 64 bit
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for (k, v) in &self.values {
            for b in k.bytes().chain([b'=']).chain(v.render().bytes()).chain([0]) {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
        format!("{h:016x}")
    }

    /// The `--set` overrides of this run.
    #[must_use]
    pub fn overrides(&self) -> Vec<String> {
        self.values
            .iter()
            .map(|(k, v)| format!("{k}={}", v.render()))
            .collect()
    }
}

fn range_value(from: f64, to: f64, log: bool, u: f64) -> f64 {
    if log {
        10f64.powf(from.log10() + u * (to.log10() - from.log10()))
    } else {
        from + u * (to - from)
    }
}

/// The runs of a spec, in order.
#[must_use]
pub fn points(spec: &Spec) -> Vec<Point> {
    match spec.design {
        Design::Grid => {
            let axes: Vec<Vec<Value>> = spec
                .parameters
                .iter()
                .map(|(_, v)| match v {
                    Values::List(l) => l.clone(),
                    // refused by the parser: a distribution has no grid
                    Values::Dist(_) => vec![Value::Num(f64::NAN)],
                    Values::Range { from, to, n, log } => {
                        let n = (*n).max(1);
                        (0..n)
                            .map(|i| {
                                #[allow(clippy::cast_precision_loss)]
                                let u = if n == 1 {
                                    0.0
                                } else {
                                    i as f64 / (n - 1) as f64
                                };
                                Value::Num(range_value(*from, *to, *log, u))
                            })
                            .collect()
                    }
                })
                .collect();
            let total = run_count(spec);
            (0..total)
                .map(|index| {
                    let mut rest = index;
                    let mut values = vec![Value::Num(0.0); axes.len()];
                    for (j, axis) in axes.iter().enumerate().rev() {
                        values[j] = axis[rest % axis.len()].clone();
                        rest /= axis.len();
                    }
                    Point {
                        index,
                        values: spec
                            .parameters
                            .iter()
                            .map(|(k, _)| k.clone())
                            .zip(values)
                            .collect(),
                    }
                })
                .collect()
        }
        Design::Lhs { samples, seed } | Design::MonteCarlo { samples, seed } => {
            let lhs = matches!(spec.design, Design::Lhs { .. });
            let mut rng = SplitMix(seed);
            // one random permutation of the strata per parameter (Monte Carlo: u at random)
            let mut columns: Vec<Vec<Value>> = spec
                .parameters
                .iter()
                .map(|(_, v)| {
                    let mut strata: Vec<usize> = (0..samples).collect();
                    if lhs {
                        for i in (1..samples).rev() {
                            strata.swap(i, rng.below(i + 1));
                        }
                    }
                    strata
                        .into_iter()
                        .map(|s| {
                            #[allow(clippy::cast_precision_loss)]
                            let u = if lhs {
                                (s as f64 + rng.unit()) / samples as f64
                            } else {
                                rng.unit()
                            };
                            // strictly inside (0, 1): the inverse distribution functions
                            let u = u.clamp(1e-12, 1.0 - 1e-12);
                            match v {
                                Values::Dist(d) => Value::Num(d.at(u)),
                                Values::Range { from, to, log, .. } => {
                                    Value::Num(range_value(*from, *to, *log, u))
                                }
                                Values::List(l) => {
                                    #[allow(
                                        clippy::cast_possible_truncation,
                                        clippy::cast_sign_loss,
                                        clippy::cast_precision_loss
                                    )]
                                    let i = ((u * l.len() as f64) as usize).min(l.len() - 1);
                                    l[i].clone()
                                }
                            }
                        })
                        .collect()
                })
                .collect();
            // a fit's components: z → p̂ + L z, sample by sample
            if let Some(ff) = &spec.from_fit {
                let idx: Vec<usize> = (0..ff.mean.len())
                    .filter_map(|k| {
                        spec.parameters
                            .iter()
                            .position(|(_, v)| matches!(v, Values::Dist(super::uncertainty::Dist::FromFit(j)) if *j == k))
                    })
                    .collect();
                if idx.len() == ff.mean.len() {
                    #[allow(clippy::needless_range_loop)]
                    for i in 0..samples {
                        let z: Vec<f64> = idx
                            .iter()
                            .map(|&j| match columns[j][i] {
                                Value::Num(z) => z,
                                Value::Text(_) => 0.0,
                            })
                            .collect();
                        for (x, &j) in ff.sample(&z).into_iter().zip(&idx) {
                            columns[j][i] = Value::Num(x);
                        }
                    }
                }
            }
            (0..samples)
                .map(|index| Point {
                    index,
                    values: spec
                        .parameters
                        .iter()
                        .zip(&columns)
                        .map(|((k, _), c)| (k.clone(), c[index].clone()))
                        .collect(),
                })
                .collect()
        }
    }
}

/// SplitMix64 (Steele, Lea & Flood 2014): small, seedable, and the same on every platform.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        #[allow(clippy::cast_precision_loss)]
        let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        u
    }
    fn below(&mut self, n: usize) -> usize {
        #[allow(clippy::cast_possible_truncation)]
        let i = (self.next() % n as u64) as usize;
        i
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::sweep::parse_spec;

    #[test]
    fn grid_varies_the_last_parameter_fastest() {
        let s = parse_spec(
            "s",
            "[parameters]\nk = [1, 2]\nc = { from = 0.0, to = 1.0, n = 3 }\n",
        )
        .unwrap();
        let p = points(&s);
        assert_eq!(p.len(), 6);
        assert_eq!(p[1].overrides(), ["parameters.k=1.0", "parameters.c=0.5"]);
        assert_eq!(p[3].overrides(), ["parameters.k=2.0", "parameters.c=0.0"]);
        let e = parse_spec("s", "[parameters]\nc = { from = 0.0, to = 1.0 }\n").unwrap_err();
        assert!(e.message.contains("needs n"), "{e}");
    }

    #[test]
    fn lhs_puts_one_sample_in_each_stratum_and_is_reproducible() {
        let text = "[sweep]\ndesign = \"lhs\"\nsamples = 8\nseed = 3\n[parameters]\na = { from = 0.0, to = 8.0 }\nb = { from = 0.0, to = 8.0 }\n";
        let s = parse_spec("s", text).unwrap();
        let p = points(&s);
        for j in 0..2 {
            let mut strata: Vec<usize> = p
                .iter()
                .map(|q| match q.values[j].1 {
                    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
                    Value::Num(v) => v.floor() as usize,
                    Value::Text(_) => usize::MAX,
                })
                .collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..8).collect::<Vec<_>>());
        }
        let again = points(&s);
        assert_eq!(p[5].id(), again[5].id());
    }
}
