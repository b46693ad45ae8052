//! Loading (and so `bg-sim check`) is linear in a model's size (issue 37, item 8): names
//! are looked up in hash maps, not by scanning every entry for every bond. Measured as a
//! ratio in one process, not an absolute time: 40 000 elements may take at most 25 times as
//! long as 4 000 (linear is 10; the scans made it 100 and more).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::time::Instant;

use bg_model::{Model, Registry};

/// `n` flow sources, each filling its own capacitor: 2n elements, n bonds.
fn chain(n: usize) -> String {
    let mut t = String::from("[elements]\n");
    for i in 0..n {
        t.push_str(&format!(
            "s{i} = {{ kind = \"Sf\", f = 1.0 }}\nc{i} = {{ kind = \"C\", c = 1.0 }}\n"
        ));
    }
    t.push_str("[bonds]\n");
    for i in 0..n {
        t.push_str(&format!("b{i} = \"s{i} -> c{i}\"\n"));
    }
    t.push_str("[simulation]\nt_end = 1.0\n");
    t
}

/// The fastest of three loads of `text`, in seconds.
fn load_time(text: &str) -> f64 {
    (0..3)
        .map(|_| {
            let t0 = Instant::now();
            let m = Model::from_text("big.toml", text, &Registry::with_core(), &[]).unwrap();
            let dt = t0.elapsed().as_secs_f64();
            assert!(!m.x0.is_empty());
            dt
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn loading_is_linear_in_the_number_of_elements() {
    let small = chain(2_000); // 4 000 elements
    let large = chain(20_000); // 40 000 elements
    let (ts, tl) = (load_time(&small), load_time(&large));
    let ratio = tl / ts;
    eprintln!("4 000 elements: {ts:.3} s, 40 000: {tl:.3} s, ratio {ratio:.1}");
    assert!(ratio < 25.0, "40 000 elements took {ratio:.1} times 4 000");
}
