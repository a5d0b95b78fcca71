//! Engine-order amplitudes of a signal sampled uniformly in crank angle (a DFT at a few bins).

/// Amplitude of engine order `order` (cycles per crank revolution) of `samples` taken at crank
/// angles `2π n / samples_per_rev`. The samples must span a whole number of periods of the order
/// (e.g. two revolutions for half orders); otherwise `None`.
pub fn order_amplitude(samples: &[f64], samples_per_rev: usize, order: f64) -> Option<f64> {
    let n = samples.len();
    if n == 0 || samples_per_rev == 0 {
        return None;
    }
    let periods = order * n as f64 / samples_per_rev as f64;
    if (periods - periods.round()).abs() > 1e-9 {
        return None;
    }
    let step = 2.0 * std::f64::consts::PI * order / samples_per_rev as f64;
    let (mut re, mut im) = (0.0, 0.0);
    for (k, x) in samples.iter().enumerate() {
        let (s, c) = (step * k as f64).sin_cos();
        re += x * c;
        im -= x * s;
    }
    let scale = if order == 0.0 { 1.0 } else { 2.0 };
    Some(scale * re.hypot(im) / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_amplitudes_of_a_known_signal() {
        let spr = 360;
        let x: Vec<f64> = (0..2 * spr)
            .map(|k| {
                let p = 2.0 * std::f64::consts::PI * k as f64 / spr as f64;
                0.5 + 3.0 * (1.5 * p + 0.3).cos() + 0.2 * (2.0 * p).sin()
            })
            .collect();
        let a = |o| order_amplitude(&x, spr, o).expect("whole periods");
        assert!((a(0.0) - 0.5).abs() < 1e-12);
        assert!((a(1.5) - 3.0).abs() < 1e-12);
        assert!((a(2.0) - 0.2).abs() < 1e-12);
        assert!(a(1.0).abs() < 1e-12);
        assert!(order_amplitude(&x[..spr], spr, 1.5).is_none());
    }
}
