//! Stability-limit detection for lightly damped oscillatory modes.
//!
//! BDF3–5 are unstable in a band of `h * omega` near the imaginary axis. When a lightly damped
//! stiff mode falls in that band the error test keeps failing at order >= 3 while the step size
//! stays stuck (CVODE's own order selection then stalls at the band edge whatever the
//! tolerance). The guard:
//!
//! - triggers when, within the last 100 steps, 5 distinct steps at order >= 3 failed the error
//!   test with step sizes inside a factor-4 band (a growing or collapsing step is not a stall);
//! - then caps the order at 2 (A-stable, damps the mode) for a hold of 100 steps;
//! - 30 steps after the hold ends it compares the mean step since the release with the mean step
//!   of the failing window: if the stall was not broken, accuracy rather than stability limits
//!   the step and the guard locks itself out (500 steps, doubling on each repeat); if it was
//!   broken but the failures recur soon, the next hold is twice as long (at most 3200 steps).

/// Steps with failures at order >= 3 needed inside the window to trigger the cap.
const TRIGGER_FAILURES: usize = 5;
/// Window length in accepted steps.
const WINDOW_STEPS: u64 = 100;
/// Largest ratio between failing step sizes that still counts as a stuck step.
const STUCK_BAND: f64 = 4.0;
/// First hold length in accepted steps.
const INITIAL_HOLD: u64 = 100;
/// Longest hold.
const MAX_HOLD: u64 = 3200;
/// Order allowed while the cap holds.
const CAPPED_ORDER: usize = 2;
/// Steps after the end of a hold at which the guard checks that the hold paid off.
const PROBE_STEPS: u64 = 30;
/// The hold paid off when the mean step after it is at least this multiple of the mean step over
/// the failing window before it.
const PAYOFF_GROWTH: f64 = 1.0;
/// First lock-out after a cap that did not pay off (accepted steps); doubles on each repeat.
const INITIAL_LOCKOUT: u64 = 500;

/// State of the detector; part of the integrator snapshot.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StabilityGuard {
    /// (step count, step size, time) of recent error-test failures at q >= 3.
    pub(crate) failures: Vec<(u64, f64, f64)>,
    pub(crate) hold_until: u64,
    pub(crate) hold_len: u64,
    pub(crate) last_release: Option<u64>,
    pub(crate) triggers: u64,
    /// Mean step over the failing window before the current hold.
    pub(crate) h_trigger: f64,
    /// Step count at which the current hold started.
    pub(crate) hold_start: u64,
    /// Time at which the current hold started.
    pub(crate) t_hold_start: f64,
    /// Time at which the last hold ended.
    pub(crate) t_release: f64,
    /// No new hold before this step count (a hold did not pay off recently).
    pub(crate) lockout_until: u64,
    pub(crate) lockout_len: u64,
}

impl Default for StabilityGuard {
    fn default() -> Self {
        Self {
            failures: Vec::new(),
            hold_until: 0,
            hold_len: INITIAL_HOLD,
            last_release: None,
            triggers: 0,
            h_trigger: 0.0,
            hold_start: 0,
            t_hold_start: 0.0,
            t_release: 0.0,
            lockout_until: 0,
            lockout_len: INITIAL_LOCKOUT,
        }
    }
}

impl StabilityGuard {
    /// Records an error-test failure of a step attempted at order `q` with size `h` from time
    /// `t` when `nst` steps had been accepted.
    pub fn record_error_test_failure(&mut self, nst: u64, t: f64, q: usize, h: f64) {
        if q < 3 || nst < self.hold_until || nst < self.lockout_until {
            return;
        }
        self.failures.retain(|(n, _, _)| n + WINDOW_STEPS >= nst);
        self.failures.push((nst, h, t));
        // Several failures on one step are ordinary step-size recovery; the instability shows
        // as failures on distinct steps.
        let mut distinct_steps = 1;
        for pair in self.failures.windows(2) {
            if pair[1].0 != pair[0].0 {
                distinct_steps += 1;
            }
        }
        if distinct_steps < TRIGGER_FAILURES {
            return;
        }
        // The step is stuck in a narrow band (it neither grows with the solution's time scale
        // nor collapses for accuracy): the signature of an order-related stability limit.
        let h_min = self
            .failures
            .iter()
            .map(|f| f.1)
            .fold(f64::INFINITY, f64::min);
        let h_max = self.failures.iter().map(|f| f.1).fold(0.0, f64::max);
        if h > self.failures[0].1 * 1.5 || h_max > STUCK_BAND * h_min {
            return;
        }
        if let Some(released) = self.last_release {
            if nst < released + 2 * self.hold_len {
                self.hold_len = (self.hold_len * 2).min(MAX_HOLD);
            }
        }
        self.hold_until = nst + self.hold_len;
        self.hold_start = nst;
        self.t_hold_start = t;
        // Mean step over the failing window: the rate of progress the hold has to beat.
        let (n0, _, t0) = self.failures[0];
        self.h_trigger = if nst > n0 {
            (t - t0) / (nst - n0) as f64
        } else {
            h_max
        };
        self.failures.clear();
        self.triggers += 1;
    }

    /// Notes an accepted step ending at `t`: detects the end of a hold and, a little later,
    /// whether it paid off. A hold pays off when the steps after it are clearly longer than the
    /// stuck steps before it (the stall is broken); otherwise accuracy, not stability, limits
    /// the step and the guard locks itself out for a while.
    pub fn on_step_accepted(&mut self, nst: u64, t: f64) {
        if self.hold_until != 0 && nst == self.hold_until {
            self.last_release = Some(nst);
            self.t_release = t;
        }
        if self.hold_until != 0 && nst == self.hold_until + PROBE_STEPS {
            let mean_h = (t - self.t_release) / PROBE_STEPS as f64;
            if mean_h < PAYOFF_GROWTH * self.h_trigger {
                self.lockout_until = nst + self.lockout_len;
                self.lockout_len = self.lockout_len.saturating_mul(2);
                self.hold_len = INITIAL_HOLD;
                self.last_release = None;
            }
        }
    }

    /// Highest order allowed for the step after `nst` accepted steps.
    pub fn order_cap(&self, nst: u64, max_order: usize) -> usize {
        if nst < self.hold_until {
            CAPPED_ORDER.min(max_order)
        } else {
            max_order
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caps_after_repeated_failures_and_releases_later() {
        let mut g = StabilityGuard::default();
        for k in 0..4 {
            g.record_error_test_failure(10 + 2 * k, 0.0, 4, 1e-3);
        }
        assert_eq!(g.order_cap(17, 5), 5);
        g.record_error_test_failure(14, 0.0, 3, 0.9e-3);
        assert_eq!(g.order_cap(15, 5), 2);
        assert_eq!(g.order_cap(14 + INITIAL_HOLD - 1, 5), 2);
        assert_eq!(g.order_cap(14 + INITIAL_HOLD, 5), 5);
    }

    #[test]
    fn ignores_repeated_failures_of_one_step() {
        let mut g = StabilityGuard::default();
        for _ in 0..5 {
            g.record_error_test_failure(10, 0.0, 5, 1e-3);
        }
        assert_eq!(g.order_cap(11, 5), 5);
    }

    #[test]
    fn ignores_low_order_and_spread_out_failures() {
        let mut g = StabilityGuard::default();
        for k in 0..10 {
            g.record_error_test_failure(k, 0.0, 2, 1e-3);
        }
        assert_eq!(g.order_cap(11, 5), 5);
        for k in 0..8 {
            g.record_error_test_failure(150 * k, 0.0, 5, 1e-3);
        }
        assert_eq!(g.order_cap(1051, 5), 5);
        // Failing steps spread over decades are a growing solution time scale, not a limit.
        let mut g = StabilityGuard::default();
        for k in 0..8 {
            g.record_error_test_failure(200 + k, 0.0, 4, 1e-3 * 0.5_f64.powi(k as i32));
        }
        assert_eq!(g.order_cap(210, 5), 5);
    }

    #[test]
    fn a_hold_that_does_not_break_the_stall_locks_the_guard_out() {
        let mut g = StabilityGuard::default();
        // Stuck at h = 1e-3 (one step per 1e-3 s) with failures every other step.
        let mut t = 0.0;
        for k in 0..5u64 {
            g.record_error_test_failure(2 * k, t, 4, 1e-3);
            t += 2e-3;
        }
        assert_eq!(g.order_cap(9, 5), 2);
        let start = 8 + INITIAL_HOLD;
        // After the hold the step is shorter than before: no payoff.
        let mut nst = 8;
        while nst <= start + PROBE_STEPS {
            g.on_step_accepted(nst, t);
            nst += 1;
            t += 0.8e-3;
        }
        for k in 0..5u64 {
            g.record_error_test_failure(nst + k, t, 4, 1e-3);
        }
        assert_eq!(
            g.order_cap(nst + 6, 5),
            5,
            "locked out after a hold that did not pay off"
        );
    }

    #[test]
    fn a_hold_that_breaks_the_stall_is_kept_and_lengthened_on_recurrence() {
        let mut g = StabilityGuard::default();
        let mut t = 0.0;
        for k in 0..5u64 {
            g.record_error_test_failure(2 * k, t, 4, 1e-3);
            t += 2e-3;
        }
        let mut nst = 8;
        while nst <= 8 + INITIAL_HOLD + PROBE_STEPS {
            g.on_step_accepted(nst, t);
            nst += 1;
            t += 5e-3;
        }
        for k in 0..5u64 {
            g.record_error_test_failure(nst + k, t, 4, 1e-3);
        }
        let trigger = nst + 4;
        assert_eq!(g.order_cap(trigger + 1, 5), 2);
        assert_eq!(
            g.order_cap(trigger + 2 * INITIAL_HOLD - 1, 5),
            2,
            "the second hold is twice as long"
        );
    }
}
