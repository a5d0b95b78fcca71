//! The split-against-monolithic criterion of the coupling tests (the 2.0 pair in
//! `tests/runtime/coupling.rs`, the 3.0 pair in `tests/fmi/fmi3_coupling.rs`): per signal, the
//! amplitudes of the half orders 0.5..6 over the last revolutions, and the relative deviation of
//! every order above 1 % of its signal's largest in the reference.

#![allow(dead_code)] // each test binary uses part of it

use engine_mount_chassis::model::orders::order_amplitude;

/// The half orders compared: 0.5, 1, ..., 6.
pub const HALF_ORDERS: usize = 12;

/// Per signal, the amplitudes of the half orders 0.5..6 over the last `revolutions` of `samples`
/// (one row per sample, `per_rev` samples per crank revolution).
pub fn orders(samples: &[Vec<f64>], per_rev: usize, revolutions: usize) -> Vec<Vec<f64>> {
    let n = per_rev * revolutions;
    let tail = &samples[samples.len() - n..];
    (0..tail[0].len())
        .map(|c| {
            let x: Vec<f64> = tail.iter().map(|s| s[c]).collect();
            (1..=HALF_ORDERS)
                .map(|k| order_amplitude(&x, per_rev, k as f64 * 0.5).unwrap())
                .collect()
        })
        .collect()
}

/// One order of one signal, compared.
#[derive(Debug, Clone, Copy)]
pub struct OrderDeviation {
    /// Index of the signal (column of the samples).
    pub signal: usize,
    /// The engine order, 0.5..6.
    pub order: f64,
    /// Its amplitude in the reference.
    pub reference: f64,
    /// Its amplitude in the run.
    pub run: f64,
    /// |run − reference| / reference.
    pub relative: f64,
}

/// Every order of every signal that reaches 1 % of its signal's largest order in `reference`,
/// with the deviation of `run` from it (both sampled alike).
pub fn order_deviations(
    reference: &[Vec<f64>],
    run: &[Vec<f64>],
    per_rev: usize,
    revolutions: usize,
) -> Vec<OrderDeviation> {
    let (oa, ob) = (
        orders(reference, per_rev, revolutions),
        orders(run, per_rev, revolutions),
    );
    let mut out = Vec::new();
    for (signal, (xa, xb)) in oa.iter().zip(&ob).enumerate() {
        let largest = xa.iter().fold(0.0f64, |m, x| m.max(*x));
        for (k, (&ya, &yb)) in xa.iter().zip(xb).enumerate() {
            if ya < 0.01 * largest {
                continue;
            }
            out.push(OrderDeviation {
                signal,
                order: (k + 1) as f64 * 0.5,
                reference: ya,
                run: yb,
                relative: if yb.is_finite() {
                    (yb - ya).abs() / ya
                } else {
                    f64::INFINITY
                },
            });
        }
    }
    out
}

/// Per half order, the largest deviation over the signals (NaN where no signal reaches the
/// 1 % floor): the line a test prints for its report.
pub fn largest_per_order(deviations: &[OrderDeviation]) -> [f64; HALF_ORDERS] {
    let mut worst = [f64::NAN; HALF_ORDERS];
    for d in deviations {
        let k = (d.order * 2.0).round() as usize - 1;
        worst[k] = if worst[k].is_nan() {
            d.relative
        } else {
            worst[k].max(d.relative)
        };
    }
    worst
}

/// Asserts every deviation below `bound` (relative), naming the signal and order of the first
/// beyond it; returns the largest.
pub fn assert_within(deviations: &[OrderDeviation], bound: f64, what: &str) -> f64 {
    let mut worst = 0.0f64;
    for d in deviations {
        worst = worst.max(d.relative);
        assert!(
            d.relative < bound,
            "{what}, signal {}, order {}: split {:.5e} vs scene 2 {:.5e} ({:.2} %)",
            d.signal,
            d.order,
            d.run,
            d.reference,
            d.relative * 100.0
        );
    }
    worst
}
