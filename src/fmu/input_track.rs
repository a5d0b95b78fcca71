//! How a continuous Real input continues between communication points.
//!
//! FMI 2.0 lets a master set an input's value (`fmi2SetReal`) and its first time derivative
//! (`fmi2SetRealInputDerivatives`) before `fmi2DoStep`. Masters differ: some send both at every
//! step, most send values only, some send a value once. The rule here, applied when a step
//! starts ([`InputTrack::commit`]), gives every master the signal it most likely means, and does
//! not depend on the order of the two calls within a step:
//!
//! - value and derivative set: the ramp they describe;
//! - derivative set alone: the same ramp from the value the signal has reached (no jump);
//! - value set alone: a first-order hold. If the last three values set lie on one line within
//!   [`SMOOTH_SLOPE_TOLERANCE`] (a master stepping a smooth signal), the signal continues with the
//!   slope of the last two, which reproduces a ramp exactly; otherwise (a step, noise, the first
//!   values) the value is held;
//! - nothing set: the signal in force continues, derivative included. A master that stops sending
//!   derivatives but keeps sending values gets the first-order hold above.
//!
//! A ramp that would leave the variable's declared range within the step is bent to end on the
//! bound at the end of the step, and stays there until the master sets something else;
//! [`Commit::clipped`] says so, for a warning. The signal never leaves the declared range: its
//! value is clamped to the range it was committed with, so the value read back at the end of
//! the step is the bound itself, not a rounding error beyond it.

/// Largest relative difference of two consecutive estimated slopes for which the values are taken
/// as samples of a smooth signal and extrapolated.
pub const SMOOTH_SLOPE_TOLERANCE: f64 = 0.25;

/// One continuous Real input: the linear signal in force and what the master set since.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct InputTrack {
    /// Value at `since`.
    pub value: f64,
    /// Slope from `since` on (per second).
    pub slope: f64,
    /// Time in s from which `value` and `slope` describe the signal (the last commit).
    pub since: f64,
    /// Set by the master since the last communication point.
    pub pending_value: Option<f64>,
    /// Slope (per s) set by `fmi2SetRealInputDerivatives` since the last communication point.
    pub pending_slope: Option<f64>,
    /// The last value the master set and when (for the slope estimate).
    pub last_set: Option<(f64, f64)>,
    /// The slope between the two values set before the last one.
    pub last_slope: Option<f64>,
    /// The declared range the signal was committed with (it never leaves it).
    pub lo: f64,
    /// Upper end of that range.
    pub hi: f64,
    /// A ramp bent onto a bound: from this time on the signal is the bound itself.
    pub landing: Option<(f64, f64)>,
}

/// What a commit decided.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Commit {
    /// The slope came from the values (first-order hold), not from the master.
    pub estimated: bool,
    /// The ramp was bent to stay in the declared range; the bound it now ends on.
    pub clipped: Option<f64>,
    /// The slope the master asked for (or the estimate), before any bending.
    pub requested_slope: f64,
}

impl InputTrack {
    /// A constant signal.
    pub fn constant(value: f64, since: f64) -> Self {
        Self {
            value,
            slope: 0.0,
            since,
            pending_value: None,
            pending_slope: None,
            last_set: None,
            last_slope: None,
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
            landing: None,
        }
    }

    /// Value at `t`.
    pub fn at(&self, t: f64) -> f64 {
        if let Some((time, bound)) = self.landing {
            if t >= time - 1e-12 * time.abs().max(1.0) {
                return bound;
            }
        }
        let x = self.value + self.slope * (t - self.since);
        if x.is_nan() {
            x
        } else {
            x.max(self.lo).min(self.hi)
        }
    }

    /// The value the master will see after the next commit if it sets nothing else: the pending
    /// value, or where the signal is at `t`.
    pub fn value_to_commit(&self, t: f64) -> f64 {
        self.pending_value.unwrap_or_else(|| self.at(t))
    }

    /// Records a value set by `fmi2SetReal`; it takes effect at the next commit.
    pub fn set_value(&mut self, value: f64) {
        self.pending_value = Some(value);
    }

    /// Records a first derivative (per s) set by `fmi2SetRealInputDerivatives`; it takes effect
    /// at the next commit.
    pub fn set_slope(&mut self, slope: f64) {
        self.pending_slope = Some(slope);
    }

    /// The signal the next step will use, without committing (for validation).
    pub fn preview(&self, t: f64) -> (f64, f64) {
        let mut copy = *self;
        copy.commit(t, 0.0, f64::NEG_INFINITY, f64::INFINITY);
        (copy.value, copy.slope)
    }

    /// Starts the step `[t, t + step]`: turns what the master set into the signal in force and
    /// keeps it within `[min, max]` over the step.
    pub fn commit(&mut self, t: f64, step: f64, min: f64, max: f64) -> Commit {
        let mut estimated = false;
        let value = self.value_to_commit(t);
        let slope = match (self.pending_slope, self.pending_value) {
            (Some(slope), _) => slope,
            (None, Some(v)) => {
                estimated = true;
                self.estimate_slope(t, v)
            }
            (None, None) => self.slope,
        };
        if let Some(v) = self.pending_value {
            if let Some((t_last, v_last)) = self.last_set {
                if t > t_last {
                    self.last_slope = Some((v - v_last) / (t - t_last));
                }
            }
            self.last_set = Some((t, v));
        }
        let nothing_set = self.pending_value.is_none() && self.pending_slope.is_none();
        self.value = value;
        // A ramp that was bent onto a bound stays there until the master says otherwise.
        let pushes_out = (value >= max && slope > 0.0) || (value <= min && slope < 0.0);
        self.slope = if nothing_set && pushes_out {
            0.0
        } else {
            slope
        };
        self.since = t;
        self.pending_value = None;
        self.pending_slope = None;
        self.lo = min;
        self.hi = max;
        self.landing = None;
        let end = self.value + self.slope * step;
        let clipped = if step > 0.0 && end > max {
            Some(max)
        } else if step > 0.0 && end < min {
            Some(min)
        } else {
            None
        };
        if let Some(bound) = clipped {
            self.slope = slope_onto(self.value, bound, step, min, max);
            self.landing = Some((t + step, bound));
        }
        Commit {
            estimated,
            clipped,
            requested_slope: slope,
        }
    }

    /// First-order hold: the slope of the last two values if the last three lie on one line,
    /// else zero.
    fn estimate_slope(&self, t: f64, v: f64) -> f64 {
        let Some((t_last, v_last)) = self.last_set else {
            return 0.0;
        };
        if t <= t_last {
            return self.slope;
        }
        let slope = (v - v_last) / (t - t_last);
        match self.last_slope {
            Some(previous)
                if (slope - previous).abs()
                    <= SMOOTH_SLOPE_TOLERANCE * slope.abs().max(previous.abs()) =>
            {
                slope
            }
            _ => 0.0,
        }
    }
}

/// The slope from `value` to `bound` over `step`, shortened by units in the last place until
/// the linear ramp evaluated at the end of the step stays within `[min, max]` (rounding would
/// otherwise leave it a few ulps beyond the bound).
fn slope_onto(value: f64, bound: f64, step: f64, min: f64, max: f64) -> f64 {
    let mut slope = (bound - value) / step;
    for _ in 0..64 {
        let end = value + slope * step;
        if (min..=max).contains(&end) || slope == 0.0 {
            break;
        }
        // One ulp toward zero, for either sign.
        slope = f64::from_bits(slope.to_bits() - 1);
    }
    slope
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(track: &mut InputTrack, t: f64, h: f64) -> Commit {
        track.commit(t, h, f64::NEG_INFINITY, f64::INFINITY)
    }

    #[test]
    fn values_of_a_ramp_are_continued_exactly_from_the_third_value_on() {
        let mut track = InputTrack::constant(800.0, 0.0);
        let h = 1e-3;
        let ramp = |t: f64| 800.0 + 170.0 * t;
        for k in 0..10 {
            let t = k as f64 * h;
            // the signal in force reaches the master's next value (no jump) once extrapolating
            if k >= 3 {
                assert!((track.at(t) - ramp(t)).abs() < 1e-9, "k = {k}");
            }
            track.set_value(ramp(t));
            let c = step(&mut track, t, h);
            assert!(c.estimated);
            if k >= 2 {
                assert!(
                    (track.slope - 170.0).abs() < 1e-6,
                    "k = {k}: {}",
                    track.slope
                );
            } else {
                assert_eq!(track.slope, 0.0);
            }
        }
    }

    #[test]
    fn a_step_in_the_values_is_held_not_extrapolated() {
        let mut track = InputTrack::constant(800.0, 0.0);
        for (k, v) in [800.0, 800.0, 2500.0, 2500.0, 2500.0].iter().enumerate() {
            track.set_value(*v);
            step(&mut track, k as f64 * 1e-3, 1e-3);
            assert_eq!(track.slope, 0.0, "k = {k}");
            assert_eq!(track.value, *v);
        }
    }

    #[test]
    fn call_order_within_a_step_does_not_matter() {
        let mut a = InputTrack::constant(800.0, 0.0);
        let mut b = a;
        a.set_value(900.0);
        a.set_slope(50.0);
        b.set_slope(50.0);
        b.set_value(900.0);
        step(&mut a, 0.1, 0.01);
        step(&mut b, 0.1, 0.01);
        assert_eq!(a, b);
        assert_eq!((a.value, a.slope), (900.0, 50.0));
    }

    #[test]
    fn a_derivative_continues_until_the_master_says_otherwise() {
        let mut track = InputTrack::constant(800.0, 0.0);
        track.set_value(800.0);
        track.set_slope(100.0);
        step(&mut track, 0.0, 0.1);
        // nothing set for two steps: the ramp goes on
        step(&mut track, 0.1, 0.1);
        step(&mut track, 0.2, 0.1);
        assert!((track.at(0.3) - 830.0).abs() < 1e-12);
        // a derivative alone starts from where the signal is
        track.set_slope(0.0);
        step(&mut track, 0.3, 0.1);
        assert!((track.value - 830.0).abs() < 1e-12);
        assert_eq!(track.slope, 0.0);
    }

    #[test]
    fn a_ramp_is_bent_onto_the_declared_bound() {
        let mut track = InputTrack::constant(5990.0, 0.0);
        track.set_slope(1000.0);
        let c = track.commit(0.0, 0.1, 0.0, 6000.0);
        assert_eq!(c.clipped, Some(6000.0));
        assert_eq!(c.requested_slope, 1000.0);
        assert_eq!(track.at(0.1), 6000.0);
        let mut scale = InputTrack::constant(0.05, 0.0);
        scale.set_slope(-1.0);
        let c = scale.commit(0.0, 0.1, 0.0, 10.0);
        assert_eq!(c.clipped, Some(0.0));
        assert_eq!(scale.at(0.1), 0.0);
    }

    /// Issue 28: ramps down onto 0 read back -2.2e-25 and the next step failed; upward, a huge
    /// derivative left the value 7e-12 above the maximum.
    #[test]
    fn ramps_end_exactly_on_their_bound_and_stay_there() {
        for (start, slope, h, lo, hi, bound) in [
            (800.0, -1000.0, 1e-3, 0.0, 6000.0, 0.0),
            (1.0, -3.0, 1e-3, 0.0, 10.0, 0.0),
            (0.7, -1.0, 0.3, 0.0, 10.0, 0.0),
            (5999.0, 1e9, 1e-3, 0.0, 6000.0, 6000.0),
            (1234.5678, 7.77e7, 3.3e-4, 0.0, 6000.0, 6000.0),
        ] {
            let mut track = InputTrack::constant(start, 0.0);
            track.set_value(start);
            track.set_slope(slope);
            let mut t = 0.0;
            let mut reached = false;
            for _ in 0..10_000 {
                let c = track.commit(t, h, lo, hi);
                // The linear ramp itself (what the model evaluates) stays in range.
                let end = track.value + track.slope * h;
                assert!((lo..=hi).contains(&end), "{start} {slope}: {end}");
                t += h;
                assert!((lo..=hi).contains(&track.at(t)), "{start} {slope}");
                if c.clipped.is_some() || reached {
                    reached = true;
                    assert_eq!(track.at(t), bound, "{start} {slope}");
                }
                if reached && c.clipped.is_none() {
                    assert_eq!(track.slope, 0.0, "stays on the bound");
                    break;
                }
            }
            assert!(reached, "{start} {slope} never reached its bound");
        }
    }
}
