//! The periodic steady state at constant inputs, found by shooting over one working cycle.
//!
//! The running engine repeats its excitation after one working cycle `T` (two crank revolutions
//! for a four-stroke engine). The vibration state `x` (powertrain positions and velocities, body
//! modal coordinates and rates) on the periodic orbit is the fixed point of the cycle map `Φ`:
//! integrate from `x` over `T` with the crank turning at the set-point speed from its start
//! angle. Newton's equation `(I − Φ'(x)) δ = Φ(x) − x` is solved with a fixed approximation
//! `P ≈ Φ'`: the vibration block of `exp(Ā T)`, `Ā` the Jacobian of the whole state (crank angle
//! included: a roll of the block moves the crank relative to it, and with it the excitation's
//! phase) averaged over the cycle's crank angles. For a linear model this is exact and the first
//! step lands on the orbit; the mounts' nonlinearity and the crank-angle-dependent inertia leave
//! a mismatch in a few directions, which Anderson acceleration of the chord iteration removes.
//! Each iteration costs one cycle of simulation; `Φ'` is never formed by simulation, and modes
//! that decay within a cycle (`exp(λT) ≈ 0`) converge in the first step whatever `P` says.
//!
//! The cycle map carries the integration error of one cycle, tens of error weights at the run's
//! tolerance (the error of a cycle is a global error). The iteration therefore switches to a
//! 1000× tighter tolerance once it reaches that floor, its acceleration restarting there (the
//! two cycle maps differ by that error), and accepts the orbit when one cycle returns to within
//! one error weight of the run's tolerance: the start is on the orbit to better than the run can
//! resolve.

use faer::Mat;
use nalgebra::DMatrix;

use crate::model::CoupledModel;
use crate::ode::{Bdf, BdfOptions, OdeProblem, Tolerance};

/// Chord-Newton iterations before giving up.
pub const MAX_ITERATIONS: usize = 12;
/// Crank angles per cycle at which the Jacobian is averaged.
const JACOBIAN_SAMPLES: usize = 8;
/// Converged when the change over one cycle is this fraction of the integrator's error weights
/// (weighted RMS norm): the orbit closes to within the integration's own accuracy.
const CLOSURE_TOLERANCE: f64 = 1.0;
/// The final iterations integrate the cycle with tolerances this much tighter than the run's.
const TIGHTENING: f64 = 1000.0;
/// Residual (error weights) below which the run's own tolerance cannot close the orbit.
const COARSE_FLOOR: f64 = 100.0;

/// A state on the periodic orbit and how it was found.
#[derive(Debug, Clone)]
pub struct PeriodicStart {
    /// The full state at the start time.
    pub state: Vec<f64>,
    /// Working-cycle period, s.
    pub period: f64,
    /// Chord-Newton iterations (each one cycle simulated).
    pub iterations: usize,
    /// Weighted RMS norm of `Φ(x) − x` at the returned state (≤ 1: within the tolerance).
    pub residual: f64,
    /// Residual of the starting guess, for the log.
    pub initial_residual: f64,
}

/// The periodic orbit through the start crank angle of `y_guess` at the model's current
/// (constant) inputs. The excitation must be fully faded in at `t0`; the caller sets that.
///
/// Long on purpose: one Newton shooting loop (residual, sensitivities through the integrator, damping, convergence test) over shared state.
pub fn periodic_start(
    model: &mut CoupledModel,
    options: &BdfOptions,
    t0: f64,
    y_guess: &[f64],
) -> Result<PeriodicStart, String> {
    let inputs = model.inputs();
    let ramps = std::iter::once(&inputs.crank_speed)
        .chain(std::iter::once(&inputs.load_torque))
        .chain(&inputs.stiffness_scale)
        .chain(&inputs.damping_scale);
    if ramps.into_iter().any(|r| r.rate != 0.0) {
        return Err(
            "a periodic start needs constant inputs at initialisation (an input derivative is set)"
                .into(),
        );
    }
    let omega = inputs.crank_speed.at(t0);
    if omega.abs() < 1.0 {
        return Err(format!(
            "a periodic start needs a running engine (crank speed {omega:.3} rad/s)"
        ));
    }
    let period = model.powertrain().cycle_angle()? / omega.abs();
    let layout = *model.layout();
    let vib = layout.vibration_coordinates();

    let mut y0 = y_guess.to_vec();
    if let Some((speed, acceleration)) = layout.follower_states() {
        y0[speed] = omega;
        y0[acceleration] = 0.0;
    }
    // The linearisation: the start guess with the crank turned through the cycle.
    let crank = layout.crank_angle();
    let rotated: Vec<(f64, Vec<f64>)> = (0..JACOBIAN_SAMPLES)
        .map(|k| {
            let dt = period * k as f64 / JACOBIAN_SAMPLES as f64;
            let mut y = y0.clone();
            y[crank] += omega * dt;
            (t0 + dt, y)
        })
        .collect();
    let chord = ChordMatrix::new(model, &rotated, &vib, period)?;

    let weights = |x: &[f64]| -> Vec<f64> {
        x.iter()
            .enumerate()
            .map(|(k, xi)| 1.0 / (options.rtol * xi.abs() + options.atol.get(vib[k])))
            .collect()
    };
    let mut x: Vec<f64> = vib.iter().map(|&i| y0[i]).collect();
    // The cycle map at the run's own tolerance carries an integration error of a few error
    // weights; once the iteration reaches that floor it continues on a tighter tolerance.
    let fine = BdfOptions {
        rtol: options.rtol / TIGHTENING,
        atol: match &options.atol {
            Tolerance::Scalar(a) => Tolerance::Scalar(a / TIGHTENING),
            Tolerance::Vector(v) => Tolerance::Vector(v.iter().map(|a| a / TIGHTENING).collect()),
        },
        ..options.clone()
    };
    let mut tight = false;
    let mut anderson = Anderson::default();
    let mut initial_residual = f64::NAN;
    let mut previous = f64::INFINITY;
    for iteration in 0..=MAX_ITERATIONS {
        let mut y = y0.clone();
        for (k, &i) in vib.iter().enumerate() {
            y[i] = x[k];
        }
        let end = one_cycle(model, if tight { &fine } else { options }, t0, &y, period)?;
        let r: Vec<f64> = vib.iter().zip(&x).map(|(&i, xi)| end[i] - xi).collect();
        let w = weights(&x);
        let residual = (r
            .iter()
            .zip(&w)
            .map(|(ri, wi)| (ri * wi).powi(2))
            .sum::<f64>()
            / r.len().max(1) as f64)
            .sqrt();
        if iteration == 0 {
            initial_residual = residual;
        }
        if !residual.is_finite() {
            return Err("the cycle map produced a non-finite state".into());
        }
        if tight && residual <= CLOSURE_TOLERANCE {
            return Ok(PeriodicStart {
                state: y,
                period,
                iterations: iteration,
                residual,
                initial_residual,
            });
        }
        if iteration == MAX_ITERATIONS {
            return Err(format!(
                "no periodic orbit after {MAX_ITERATIONS} iterations: the state changes over one \
                 cycle by {residual:.3e} error weights (from {initial_residual:.3e})"
            ));
        }
        // The run's tolerance has done what it can when the residual nears its error floor or
        // stops falling fast.
        let switching = !tight && (residual <= COARSE_FLOOR || residual > previous / 4.0);
        previous = residual;
        let step = chord.solve(&r);
        x = if switching {
            // Anderson combines the steps of one cycle map. The tight map differs from the
            // coarse one by the coarse map's integration error (tens of error weights, more than
            // the residual at the switch): a coarse step kept in the history reads as the
            // response to the iterates' differences and is cancelled, holding the state still.
            // The first tight iterate is the plain chord step; the history starts after it.
            tight = true;
            anderson.clear();
            x.iter().zip(&step).map(|(xi, si)| xi + si).collect()
        } else {
            anderson.next(&x, &step, &w)
        };
    }
    unreachable!("the loop returns on its last iteration")
}

/// Integrates the model over one cycle from `y` at `t0` with a fresh integrator.
fn one_cycle(
    model: &mut CoupledModel,
    options: &BdfOptions,
    t0: f64,
    y: &[f64],
    period: f64,
) -> Result<Vec<f64>, String> {
    let mut bdf = Bdf::new(model, t0, y, options.clone()).map_err(|e| e.to_string())?;
    bdf.advance_to(model, t0 + period)
        .map_err(|e| format!("simulating one cycle: {e}"))?;
    Ok(bdf.y().to_vec())
}

/// Anderson acceleration of the chord iteration `x ← g(x) = x + (I − P)⁻¹ r(x)`: the next
/// iterate combines the last few so that the combined step cancels best (weighted least
/// squares). Where `P` is a poor approximation in a few directions (a lightly damped mode near a
/// harmonic of the cycle, the roll mode's phase coupling with the crank) the plain chord
/// iteration contracts slowly or oscillates there; the combination removes those directions
/// without further simulation.
#[derive(Default)]
struct Anderson {
    /// Past (x + step, step), scaled by nothing; at most [`ANDERSON_DEPTH`] + 1 entries.
    history: Vec<(Vec<f64>, Vec<f64>)>,
}

/// Past iterates combined by [`Anderson`].
const ANDERSON_DEPTH: usize = 4;

impl Anderson {
    fn clear(&mut self) {
        self.history.clear();
    }

    /// The next iterate from `x` and its chord step; `w` weights the components.
    fn next(&mut self, x: &[f64], step: &[f64], w: &[f64]) -> Vec<f64> {
        let g: Vec<f64> = x.iter().zip(step).map(|(a, b)| a + b).collect();
        self.history.push((g.clone(), step.to_vec()));
        if self.history.len() > ANDERSON_DEPTH + 1 {
            self.history.remove(0);
        }
        let depth = self.history.len() - 1;
        if depth == 0 {
            return g;
        }
        let n = step.len();
        let (g_last, f_last) = &self.history[depth];
        let df =
            DMatrix::<f64>::from_fn(n, depth, |i, k| (f_last[i] - self.history[k].1[i]) * w[i]);
        let rhs = nalgebra::DVector::<f64>::from_fn(n, |i, _| f_last[i] * w[i]);
        let Ok(gamma) = df.svd(true, true).solve(&rhs, 1e-10) else {
            return g;
        };
        let next: Vec<f64> = (0..n)
            .map(|i| {
                g_last[i]
                    - (0..depth)
                        .map(|k| gamma[k] * (g_last[i] - self.history[k].0[i]))
                        .sum::<f64>()
            })
            .collect();
        if next.iter().all(|v| v.is_finite()) {
            next
        } else {
            g
        }
    }
}

/// `I − P` on the vibration coordinates, factorised, with `P` the vibration block of
/// `exp(Ā T)`.
struct ChordMatrix {
    lu: nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
}

impl ChordMatrix {
    /// `Ā` is the Jacobian averaged over `samples` (time, state) of one cycle. The whole state
    /// takes part, crank angle and follower included: a vibration perturbation moves the crank
    /// angle relative to the block and with it the phase of the excitation.
    fn new(
        model: &mut CoupledModel,
        samples: &[(f64, Vec<f64>)],
        vib: &[usize],
        period: f64,
    ) -> Result<Self, String> {
        let n = model.dim();
        let m = vib.len();
        let mut average = DMatrix::<f64>::zeros(n, n);
        let mut j = Mat::<f64>::zeros(n, n);
        for (t, y) in samples {
            model
                .jacobian(*t, y, j.as_mut())
                .map_err(|e| format!("linearising for the periodic start: {e:?}"))?;
            for c in 0..n {
                for r in 0..n {
                    average[(r, c)] += j[(r, c)] / samples.len() as f64;
                }
            }
        }
        let full = (average * period).exp();
        let chord = DMatrix::<f64>::from_fn(m, m, |r, c| {
            let identity = if r == c { 1.0 } else { 0.0 };
            identity - full[(vib[r], vib[c])]
        });
        if chord.iter().any(|v| !v.is_finite()) {
            return Err("the linearised cycle map is not finite".into());
        }
        Ok(Self { lu: chord.lu() })
    }

    /// `δ = (I − P)⁻¹ r`; where `I − P` is singular (an undamped mode in resonance with a cycle
    /// harmonic) the step is zero in that direction and the iteration reports no convergence.
    fn solve(&self, r: &[f64]) -> Vec<f64> {
        let rhs = nalgebra::DVector::from_column_slice(r);
        match self.lu.solve(&rhs) {
            Some(d) if d.iter().all(|v| v.is_finite()) => d.iter().copied().collect(),
            _ => vec![0.0; r.len()],
        }
    }
}
