//! Test support shared by mote's crates, a dev-dependency only: the
//! numbers a careless or hostile user writes into a scene, for the
//! property tests over scene values (every value in range runs or is
//! refused, never panics; every value out of range is refused at its line);
//! a closure run on a pool of a given number of threads, for the tests that
//! results do not depend on it.
#![forbid(unsafe_code)]

use std::ops::Range;

use proptest::prelude::*;

/// A number a careless or hostile user might write for any key: zero, a
/// negative, the extremes of f64's range, or anything of moderate size.
pub fn hostile() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(-1.0),
        Just(1e-300),
        Just(1e300),
        Just(f64::MIN_POSITIVE),
        Just(f64::MAX),
        -1e3..1e3f64,
    ]
}

/// One value per key from its `valid` range, then up to two keys (chosen
/// at random, possibly the same) replaced by [`hostile`] values.
pub fn with_hostile(valid: Vec<Range<f64>>) -> impl Strategy<Value = Vec<f64>> {
    let keys = valid.len();
    (valid, prop::collection::vec((0..keys, hostile()), 0..3)).prop_map(|(mut v, bad)| {
        for (i, x) in bad {
            v[i] = x;
        }
        v
    })
}

/// `f` run on a pool of its own with `threads` threads.
pub fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;

    /// Values stay in their ranges unless replaced, and replacements come
    /// from the hostile set: over many draws every key is seen replaced.
    #[test]
    fn hostile_values_replace_at_most_two_keys() {
        let valid = vec![1.0..2.0, 10.0..20.0, 100.0..200.0];
        let strategy = with_hostile(valid.clone());
        let mut runner = TestRunner::deterministic();
        let mut replaced = [false; 3];
        for _ in 0..500 {
            let v = strategy.new_tree(&mut runner).unwrap().current();
            let outside: Vec<usize> = (0..3).filter(|&k| !valid[k].contains(&v[k])).collect();
            assert!(outside.len() <= 2, "{v:?}");
            for k in outside {
                replaced[k] = true;
            }
        }
        assert_eq!(replaced, [true; 3]);
    }
}
