//! Side-by-side timing: medians of interleaved samples. Shared by `perf_report` and the
//! benches so both measure the same way.
#![allow(dead_code)]

use std::time::Instant;

pub struct Config {
    pub samples: usize,
    /// Target wall time of one sample (s).
    pub sample_time: f64,
}

/// Median time per call (ns) of `ours` and `reference`, sampled alternately.
pub fn compare(cfg: &Config, mut ours: impl FnMut(), mut reference: impl FnMut()) -> (f64, f64) {
    // Warm up and size the batch so one sample lasts about `sample_time`.
    ours();
    reference();
    let t = Instant::now();
    ours();
    let once = t.elapsed().as_secs_f64().max(1e-9);
    let batch = ((cfg.sample_time / once) as usize).clamp(1, 1_000_000);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..cfg.samples {
        let t = Instant::now();
        for _ in 0..batch {
            ours();
        }
        a.push(t.elapsed().as_secs_f64() * 1e9 / batch as f64);
        let t = Instant::now();
        for _ in 0..batch {
            reference();
        }
        b.push(t.elapsed().as_secs_f64() * 1e9 / batch as f64);
    }
    (median(a), median(b))
}

pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

pub fn line(name: &str, ours: f64, reference: f64, note: &str) {
    println!(
        "{name:<48} {ours:>14.1} {reference:>14.1} {:>7.3}  {note}",
        ours / reference
    );
}

/// Box3D's way of timing a scene: one untimed step, then the mean time (s) of the remaining
/// `steps - 1`.
pub fn mean_step_time(mut step: impl FnMut(), steps: usize) -> f64 {
    step();
    let t = Instant::now();
    for _ in 1..steps {
        step();
    }
    t.elapsed().as_secs_f64() / (steps.max(2) - 1) as f64
}
