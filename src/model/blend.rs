//! Smooth transitions for the model's switches in time and crank angle (excitation fade-in,
//! valve events): the integrator's error estimate assumes smooth right-hand sides.

/// `0 → 1` on `[0, 1]` with zero first and second derivatives at both ends (quintic), constant
/// outside.
pub fn smooth_step(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * x * (10.0 + x * (-15.0 + 6.0 * x))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_flat_to_the_second_derivative() {
        assert_eq!(smooth_step(-1.0), 0.0);
        assert_eq!(smooth_step(0.0), 0.0);
        assert_eq!(smooth_step(1.0), 1.0);
        assert_eq!(smooth_step(2.0), 1.0);
        assert!((smooth_step(0.5) - 0.5).abs() < 1e-15);
        let h = 1e-4;
        for x in [0.0, 1.0] {
            let d1 = (smooth_step(x + h) - smooth_step(x - h)) / (2.0 * h);
            let d2 = (smooth_step(x + h) - 2.0 * smooth_step(x) + smooth_step(x - h)) / (h * h);
            assert!(d1.abs() < 1e-7 && d2.abs() < 1e-3, "at {x}: {d1} {d2}");
        }
    }
}
