//! The variable-order, variable-step BDF stepper (CVODE's cvStep and its helpers) and the public
//! driver: stop-time landing, interpolation, restart, options.

use faer::Mat;

use super::coefficients::{bdf_coefficients, L_MAX};
use super::dense_lu::DenseLu;
use super::error::BdfError;
use super::evaluation::{eval_mass, eval_rhs};
use super::linear_solver::IterationMatrix;
use super::nordsieck::{wrms_norm, Nordsieck};
use super::options::BdfOptions;
use super::pattern::JacobianPattern;
use super::problem::{OdeProblem, ProblemError};
use super::stability::StabilityGuard;
use super::stats::BdfStats;

// Step-size control constants of CVODE (cvode.c).
pub(super) const ADDON: f64 = 1e-6;
pub(super) const BIAS1: f64 = 6.0;
pub(super) const BIAS2: f64 = 6.0;
pub(super) const BIAS3: f64 = 10.0;
pub(super) const ONEPSM: f64 = 1.000001;
pub(super) const THRESH: f64 = 1.5;
pub(super) const ETAMX1: f64 = 10000.0;
pub(super) const ETAMX2: f64 = 10.0;
pub(super) const ETAMX3: f64 = 10.0;
pub(super) const ETAMXF: f64 = 0.2;
pub(super) const ETAMIN: f64 = 0.1;
pub(super) const ETACF: f64 = 0.25;
pub(super) const SMALL_NST: u64 = 10;
pub(super) const MXNEF1: usize = 3;
pub(super) const SMALL_NEF: usize = 2;
pub(super) const LONG_WAIT: usize = 10;
pub(super) const NLS_COEF: f64 = 0.1;

/// Why the last nonlinear solve attempt ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum StepFlag {
    FirstCall,
    PrevConvFail,
    PrevErrFail,
}

/// Outcome of the Newton iteration for one step attempt.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum NlsOutcome {
    Converged,
    /// Divergence, too many iterations or a singular iteration matrix: retry with smaller h.
    ConvergenceFailure,
    /// The problem returned NaN/inf or a recoverable error: retry with smaller h.
    RhsRecoverable(ProblemError),
    /// The problem cannot continue.
    Fatal(String),
}

/// Newton iteration matrix `M - gamma J` and the Jacobian it was built from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub(super) struct LinearSystem {
    pub matrix: IterationMatrix,
    /// Step count (since the last (re)start) of the last Jacobian evaluation.
    pub nstlj: u64,
    /// Whether the Jacobian was evaluated at the current step attempt.
    pub jcur: bool,
}

/// Everything that determines the future of the integration; cloned by snapshots.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub(super) struct BdfState {
    pub opts: BdfOptions,
    pub n: usize,
    pub tn: f64,
    pub h: f64,
    pub hprime: f64,
    pub hscale: f64,
    pub eta: f64,
    pub etamax: f64,
    pub hu: f64,
    pub q: usize,
    pub qprime: usize,
    pub qwait: usize,
    pub tau: [f64; L_MAX + 1],
    pub tq: [f64; 6],
    pub l: [f64; L_MAX + 1],
    pub rl1: f64,
    pub gamma: f64,
    pub gammap: f64,
    pub gamrat: f64,
    pub crate_: f64,
    pub delp: f64,
    pub acnrm: f64,
    pub saved_tq5: f64,
    /// Steps since construction or the last restart (CVODE's nst).
    pub nst: u64,
    pub nstlp: u64,
    pub nscon: u64,
    pub zn: Nordsieck,
    /// Local error estimate of the last step (acor scaled by tq[2]).
    pub acor: Vec<f64>,
    pub lin: LinearSystem,
    pub stats: BdfStats,
    /// The first step size is still to be chosen (zn[1] holds y', not h y').
    pub pending_h0: bool,
    /// Stop time of the current call.
    pub tstop: f64,
    /// Step size the controller wanted before it was clipped to land on the stop time.
    pub h_unclipped: Option<f64>,
    pub stability: StabilityGuard,
    /// Fixed order and step (tests of the convergence order only): no adaptivity.
    pub fixed: bool,
}

/// Scratch vectors; their contents never carry over between steps.
#[derive(Debug, Clone)]
pub(super) struct Workspace {
    pub ewt: Vec<f64>,
    pub y: Vec<f64>,
    pub ftemp: Vec<f64>,
    pub tempv: Vec<f64>,
    pub delta: Vec<f64>,
    pub jac_y: Vec<f64>,
    pub jac_f: Vec<f64>,
    pub mass: Mat<f64>,
}

/// The Gear/BDF integrator. It owns no problem: each call borrows it.
#[derive(Debug, Clone)]
pub struct Bdf {
    pub(super) s: BdfState,
    pub(super) w: Workspace,
    pub(super) pattern: Option<(JacobianPattern, Vec<Vec<usize>>)>,
    pub(super) has_mass: bool,
    /// `M` when the problem declares it constant (evaluated once).
    pub(super) constant_mass: Option<Mat<f64>>,
}

fn problem_error(e: ProblemError) -> String {
    match e {
        ProblemError::NonFinite => "non-finite value".to_string(),
        ProblemError::Recoverable(m) | ProblemError::Fatal(m) => m,
    }
}

impl Bdf {
    /// Creates an integrator at `(t0, y0)`; evaluates `f(t0, y0)` (and `M`) once.
    ///
    /// Long on purpose: it sets up every part of the integrator state in the order of CVODE's cvInit, to be compared with it.
    pub fn new<P: OdeProblem>(
        problem: &mut P,
        t0: f64,
        y0: &[f64],
        opts: BdfOptions,
    ) -> Result<Self, BdfError> {
        let n = problem.dim();
        if y0.len() != n {
            return Err(BdfError::InvalidInput {
                field: "y0",
                message: format!("has {} entries, the problem has {n} states", y0.len()),
            });
        }
        if !t0.is_finite() {
            return Err(BdfError::InvalidInput {
                field: "t0",
                message: format!("must be finite, got {t0}"),
            });
        }
        if let Some(i) = y0.iter().position(|v| !v.is_finite()) {
            return Err(BdfError::InvalidInput {
                field: "y0",
                message: format!("entry {i} is {}", y0[i]),
            });
        }
        opts.validate(n)?;
        let pattern = match problem.jacobian_pattern() {
            Some(p) if p.dim() != n => {
                return Err(BdfError::InvalidInput {
                    field: "jacobian_pattern",
                    message: format!("has dimension {}, the problem has {n} states", p.dim()),
                })
            }
            Some(p) => {
                let groups = p.column_groups();
                Some((p, groups))
            }
            None => None,
        };
        let has_mass = problem.has_mass_matrix();
        let matrix = match problem.jacobian_structure() {
            None => IterationMatrix::dense(n),
            Some(shape) => {
                let invalid = |message: String| BdfError::InvalidInput {
                    field: "jacobian_structure",
                    message,
                };
                shape.validate(n).map_err(invalid)?;
                if has_mass {
                    return Err(invalid(
                        "a block-low-rank Jacobian needs M = I; this problem has a mass matrix"
                            .into(),
                    ));
                }
                IterationMatrix::block_low_rank(shape)
            }
        };
        let max_order = opts.max_order;
        let state = BdfState {
            n,
            tn: t0,
            h: 0.0,
            hprime: 0.0,
            hscale: 0.0,
            eta: 1.0,
            etamax: ETAMX1,
            hu: 0.0,
            q: 1,
            qprime: 1,
            qwait: 2,
            tau: [0.0; L_MAX + 1],
            tq: [0.0; 6],
            l: [0.0; L_MAX + 1],
            rl1: 0.0,
            gamma: 0.0,
            gammap: 0.0,
            gamrat: 1.0,
            crate_: 1.0,
            delp: 0.0,
            acnrm: 0.0,
            saved_tq5: 0.0,
            nst: 0,
            nstlp: 0,
            nscon: 0,
            zn: Nordsieck::new(n, max_order),
            acor: vec![0.0; n],
            lin: LinearSystem {
                matrix,
                nstlj: 0,
                jcur: false,
            },
            stats: BdfStats {
                order: 0,
                order_next: 1,
                ..Default::default()
            },
            pending_h0: true,
            tstop: t0,
            h_unclipped: None,
            stability: StabilityGuard::default(),
            fixed: false,
            opts,
        };
        let work = Workspace {
            ewt: vec![0.0; n],
            y: vec![0.0; n],
            ftemp: vec![0.0; n],
            tempv: vec![0.0; n],
            delta: vec![0.0; n],
            jac_y: vec![0.0; n],
            jac_f: vec![0.0; n],
            mass: Mat::zeros(if has_mass { n } else { 0 }, if has_mass { n } else { 0 }),
        };
        let mut bdf = Self {
            s: state,
            w: work,
            pattern,
            has_mass,
            constant_mass: None,
        };
        if has_mass && problem.mass_is_constant() {
            let mut m = Mat::zeros(n, n);
            problem
                .mass(t0, y0, m.as_mut())
                .map_err(|e| BdfError::ProblemFailed {
                    t: t0,
                    message: format!("mass matrix: {}", problem_error(e)),
                })?;
            if m.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
                return Err(BdfError::NonFiniteRhs { t: t0 });
            }
            bdf.constant_mass = Some(m);
        }
        bdf.load_initial_derivative(problem, y0)?;
        Ok(bdf)
    }

    /// Current time (the end of the last successful step, or the stop time reached).
    pub fn t(&self) -> f64 {
        self.s.tn
    }

    /// State at [`Self::t`].
    pub fn y(&self) -> &[f64] {
        &self.s.zn.zn[0]
    }

    /// Counters, last order and step size.
    pub fn stats(&self) -> &BdfStats {
        &self.s.stats
    }

    /// The options in force.
    pub fn options(&self) -> &BdfOptions {
        &self.s.opts
    }

    /// Estimated local error of the last step (CVODE's CVodeGetEstLocalErrors).
    pub fn local_error_estimate(&self) -> &[f64] {
        &self.s.acor
    }

    /// Replaces the options. A lower `max_order` takes effect at the next step.
    pub fn set_options(&mut self, opts: BdfOptions) -> Result<(), BdfError> {
        opts.validate(self.s.n)?;
        if opts.max_order > self.s.zn.zn.len() - 1 {
            // Grow the history; the new columns start empty and are only used once the order
            // reaches them through an order increase that fills them.
            self.s.zn.zn.resize(opts.max_order + 1, vec![0.0; self.s.n]);
            self.s.saved_tq5 = 0.0;
        } else if opts.max_order < self.s.zn.zn.len() - 1 {
            while self.s.q > opts.max_order {
                self.s
                    .zn
                    .decrease_order(self.s.q, self.s.hscale, &self.s.tau);
                self.s.q -= 1;
                self.s.qwait = self.s.q + 1;
            }
            self.s.qprime = self.s.qprime.min(opts.max_order);
            self.s.zn.zn.truncate(opts.max_order + 1);
            self.s.saved_tq5 = 0.0;
        }
        self.s.opts = opts;
        Ok(())
    }

    /// Changes only the tolerances.
    pub fn set_tolerances(
        &mut self,
        rtol: f64,
        atol: super::options::Tolerance,
    ) -> Result<(), BdfError> {
        let opts = BdfOptions {
            rtol,
            atol,
            ..self.s.opts.clone()
        };
        self.set_options(opts)
    }

    /// Restarts at order 1 at the current time (after a discontinuity), optionally from a new
    /// state. The step size is chosen afresh at the next `advance_to`.
    pub fn restart<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        y: Option<&[f64]>,
    ) -> Result<(), BdfError> {
        let y0: Vec<f64> = match y {
            Some(y) => {
                if y.len() != self.s.n {
                    return Err(BdfError::InvalidInput {
                        field: "y",
                        message: format!(
                            "has {} entries, the problem has {} states",
                            y.len(),
                            self.s.n
                        ),
                    });
                }
                if let Some(i) = y.iter().position(|v| !v.is_finite()) {
                    return Err(BdfError::InvalidInput {
                        field: "y",
                        message: format!("entry {i} is {}", y[i]),
                    });
                }
                y.to_vec()
            }
            None => self.s.zn.zn[0].clone(),
        };
        // Keep the previous state intact if the new derivative cannot be evaluated.
        let backup = self.s.clone();
        let s = &mut self.s;
        s.q = 1;
        s.qprime = 1;
        s.qwait = 2;
        s.etamax = ETAMX1;
        s.hu = 0.0;
        s.nst = 0;
        s.nstlp = 0;
        s.nscon = 0;
        s.tau = [0.0; L_MAX + 1];
        s.tq = [0.0; 6];
        s.saved_tq5 = 0.0;
        s.h_unclipped = None;
        s.lin.nstlj = 0;
        s.stability = StabilityGuard::default();
        s.stats.order_next = 1;
        s.acor.iter_mut().for_each(|v| *v = 0.0);
        for col in s.zn.zn.iter_mut().skip(2) {
            col.iter_mut().for_each(|v| *v = 0.0);
        }
        if let Err(e) = self.load_initial_derivative(problem, &y0) {
            self.s = backup;
            return Err(e);
        }
        Ok(())
    }

    /// Restarts at order 1 from state `y` at time `t`, which may lie behind the current time
    /// (the integrator stepped past an output time at which the inputs then jumped). On error
    /// the integrator is left as it was.
    pub fn restart_at<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        t: f64,
        y: &[f64],
    ) -> Result<(), BdfError> {
        if !t.is_finite() {
            return Err(BdfError::InvalidInput {
                field: "t",
                message: format!("must be finite, got {t}"),
            });
        }
        let tn = self.s.tn;
        self.s.tn = t;
        let result = self.restart(problem, Some(y));
        if result.is_err() {
            self.s.tn = tn;
        }
        result
    }

    /// Sets `zn[0] = y0`, `zn[1] = y'(t) = M^{-1} f` and marks the first step size as pending.
    fn load_initial_derivative<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        y0: &[f64],
    ) -> Result<(), BdfError> {
        let t = self.s.tn;
        let mut yp = vec![0.0; self.s.n];
        eval_rhs(problem, &mut self.s.stats, t, y0, &mut yp).map_err(|e| match e {
            ProblemError::NonFinite => BdfError::NonFiniteRhs { t },
            other => BdfError::ProblemFailed {
                t,
                message: problem_error(other),
            },
        })?;
        if self.has_mass {
            let n = self.s.n;
            let mut lu = DenseLu::new(n);
            eval_mass(problem, self.constant_mass.as_ref(), t, y0, lu.matrix_mut()).map_err(
                |e| BdfError::ProblemFailed {
                    t,
                    message: format!("mass matrix: {}", problem_error(e)),
                },
            )?;
            if !lu.factor() {
                return Err(BdfError::ProblemFailed {
                    t,
                    message: "the mass matrix is singular; the integrator needs an invertible M"
                        .to_string(),
                });
            }
            lu.solve_in_place(&mut yp);
        }
        self.s.zn.zn[0].copy_from_slice(y0);
        self.s.zn.zn[1].copy_from_slice(&yp);
        self.s.pending_h0 = true;
        self.s.h = 0.0;
        self.s.hprime = 0.0;
        Ok(())
    }

    /// Integrates up to exactly `t_stop`, keeping the history for the next call. Returns at once
    /// if `t_stop` equals the current time to within rounding.
    pub fn advance_to<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        t_stop: f64,
    ) -> Result<(), BdfError> {
        self.check_target(problem, t_stop, "t_stop")?;
        let tn = self.s.tn;
        let jitter = 100.0 * f64::EPSILON * tn.abs().max(t_stop.abs()).max(f64::MIN_POSITIVE);
        if (t_stop - tn).abs() <= jitter {
            return Ok(());
        }
        if t_stop < tn {
            return Err(BdfError::InvalidInput {
                field: "t_stop",
                message: format!(
                    "{t_stop} is behind the current time {tn}; the integrator only moves forward"
                ),
            });
        }
        self.step_until(problem, t_stop, true)
    }

    /// Steps freely until the internal time reaches or passes `t_out` (CVODE's normal mode) and
    /// writes the interpolated `y(t_out)` into `y_out`. The steps do not bend to land on `t_out`,
    /// so closely spaced output times cost no extra steps or refactorisations; `t_out` may lie
    /// anywhere in the last step taken.
    pub fn advance_past<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        t_out: f64,
        y_out: &mut [f64],
    ) -> Result<(), BdfError> {
        self.check_target(problem, t_out, "t_out")?;
        if y_out.len() != self.s.n {
            return Err(BdfError::InvalidInput {
                field: "y_out",
                message: format!(
                    "has {} entries, the problem has {} states",
                    y_out.len(),
                    self.s.n
                ),
            });
        }
        if t_out > self.s.tn {
            self.step_until(problem, t_out, false)?;
        }
        self.interpolate(t_out, 0, y_out)
    }

    fn check_target<P: OdeProblem>(
        &self,
        problem: &P,
        t: f64,
        field: &'static str,
    ) -> Result<(), BdfError> {
        if !t.is_finite() {
            return Err(BdfError::InvalidInput {
                field,
                message: format!("must be finite, got {t}"),
            });
        }
        if problem.dim() != self.s.n {
            return Err(BdfError::InvalidInput {
                field: "problem",
                message: format!(
                    "has {} states, the integrator was built for {}",
                    problem.dim(),
                    self.s.n
                ),
            });
        }
        Ok(())
    }

    /// Takes steps until `t_target` is reached (`land`: exactly, the last step shortened) or
    /// passed (`!land`).
    fn step_until<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        t_target: f64,
        land: bool,
    ) -> Result<(), BdfError> {
        // Without landing there is no stop time: no step is clipped or snapped to the target,
        // which only bounds the first step's estimate.
        self.s.tstop = if land { t_target } else { f64::INFINITY };
        if self.s.pending_h0 {
            self.initial_step(problem, t_target)?;
        }
        let mut steps = 0usize;
        loop {
            if steps >= self.s.opts.max_steps_per_call {
                return Err(BdfError::TooManySteps {
                    t: self.s.tn,
                    steps,
                });
            }
            self.set_error_weights()?;
            let tolsf = f64::EPSILON * wrms_norm(&self.s.zn.zn[0], &self.w.ewt);
            if tolsf > 1.0 {
                return Err(BdfError::TooMuchAccuracy {
                    t: self.s.tn,
                    factor: 2.0 * tolsf,
                });
            }
            if land {
                self.clip_to_stop_time();
            }
            self.step(problem)?;
            steps += 1;
            if (land && self.s.tn == self.s.tstop) || (!land && self.s.tn >= t_target) {
                return Ok(());
            }
        }
    }

    /// Ensures the next step does not pass the stop time: a step that would reach or pass it is
    /// shortened to end exactly on it.
    fn clip_to_stop_time(&mut self) {
        let s = &mut self.s;
        let remaining = s.tstop - s.tn;
        let wanted = s.hprime;
        if wanted >= remaining * (1.0 - 4.0 * f64::EPSILON) {
            s.hprime = remaining;
        } else if wanted * 2.0 > remaining {
            // Two equal steps instead of a full one followed by a sliver.
            s.hprime = 0.5 * remaining;
        } else {
            return;
        }
        s.h_unclipped = Some(s.h_unclipped.unwrap_or(0.0).max(wanted));
        s.eta = s.hprime / s.h;
    }

    /// Computes the WRMS weights from the current solution.
    pub(super) fn set_error_weights(&mut self) -> Result<(), BdfError> {
        let rtol = self.s.opts.rtol;
        for (i, (w, y)) in self.w.ewt.iter_mut().zip(&self.s.zn.zn[0]).enumerate() {
            let magnitude = match &self.s.opts.magnitude_cap {
                Some(cap) => y.abs().min(cap[i]),
                None => y.abs(),
            };
            let tol = rtol * magnitude + self.s.opts.atol.get(i);
            if tol.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || !tol.is_finite() {
                return Err(BdfError::BadErrorWeight {
                    t: self.s.tn,
                    index: i,
                });
            }
            *w = 1.0 / tol;
        }
        Ok(())
    }

    /// Chooses the first step size (CVODE's cvHin, or `h_init`), limits it and scales `zn[1]`.
    fn initial_step<P: OdeProblem>(&mut self, problem: &mut P, tout: f64) -> Result<(), BdfError> {
        self.set_error_weights()?;
        let mut h = match self.s.opts.h_init {
            Some(h) => h,
            None => self.estimate_initial_step(problem, tout)?,
        };
        h = h.min(self.s.opts.h_max).max(self.s.opts.h_min);
        let remaining = tout - self.s.tn;
        if h > remaining {
            h = remaining;
        }
        let s = &mut self.s;
        s.h = h;
        s.hprime = h;
        s.hscale = h;
        s.eta = 1.0;
        for v in s.zn.zn[1].iter_mut() {
            *v *= h;
        }
        s.pending_h0 = false;
        s.stats.h_next = h;
        Ok(())
    }

    /// CVODE's cvHin: geometric mean of bounds refined by an estimate of `y''`.
    fn estimate_initial_step<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        tout: f64,
    ) -> Result<f64, BdfError> {
        let t0 = self.s.tn;
        let tdist = (tout - t0).abs();
        let tround = f64::EPSILON * t0.abs().max(tout.abs());
        let hlb = 100.0 * tround;
        // Upper bound from |y'| relative to 0.1 |y| + atol.
        let mut hub_inv: f64 = 0.0;
        for i in 0..self.s.n {
            let y = self.s.zn.zn[0][i];
            let yp = self.s.zn.zn[1][i];
            let denom = 0.1 * y.abs() + self.s.opts.atol.get(i);
            // A component that is zero with zero absolute tolerance gives no bound.
            if denom > 0.0 {
                hub_inv = hub_inv.max(yp.abs() / denom);
            }
        }
        let mut hub = 0.1 * tdist;
        if hub * hub_inv > 1.0 {
            hub = 1.0 / hub_inv;
        }
        let mut hg = (hlb * hub).sqrt();
        if hub < hlb {
            return Ok(hg);
        }
        let mut hnew = hg;
        let mut hnew_ok = false;
        let mut hs = hg;
        for count1 in 1..=4 {
            let mut hg_ok = false;
            let mut yddnrm = 0.0;
            for _ in 0..4 {
                match self.ydd_norm(problem, hg) {
                    Ok(v) => {
                        yddnrm = v;
                        hg_ok = true;
                        break;
                    }
                    Err(ProblemError::Fatal(m)) => {
                        return Err(BdfError::ProblemFailed { t: t0, message: m })
                    }
                    Err(_) => hg *= 0.2,
                }
            }
            if !hg_ok {
                if count1 <= 2 {
                    return Err(BdfError::NonFiniteRhs { t: t0 });
                }
                hnew = hs;
                break;
            }
            hs = hg;
            if hnew_ok || count1 == 4 {
                hnew = hg;
                break;
            }
            hnew = if yddnrm * hub * hub > 2.0 {
                (2.0 / yddnrm).sqrt()
            } else {
                (hg * hub).sqrt()
            };
            let hrat = hnew / hg;
            if hrat > 0.5 && hrat < 2.0 {
                hnew_ok = true;
            }
            if count1 > 1 && hrat > 2.0 {
                hnew = hg;
                hnew_ok = true;
            }
            hg = hnew;
        }
        Ok((0.5 * hnew).clamp(hlb, hub))
    }

    /// WRMS norm of the difference estimate of `y''` over a step `hg` (cvYddNorm).
    fn ydd_norm<P: OdeProblem>(&mut self, problem: &mut P, hg: f64) -> Result<f64, ProblemError> {
        let n = self.s.n;
        let t = self.s.tn + hg;
        let mut y = vec![0.0; n];
        for i in 0..n {
            y[i] = self.s.zn.zn[0][i] + hg * self.s.zn.zn[1][i];
        }
        let mut f = vec![0.0; n];
        eval_rhs(problem, &mut self.s.stats, t, &y, &mut f)?;
        if self.has_mass {
            let mut lu = DenseLu::new(n);
            eval_mass(problem, self.constant_mass.as_ref(), t, &y, lu.matrix_mut())?;
            if !lu.factor() {
                return Err(ProblemError::Recoverable(
                    "singular mass matrix".to_string(),
                ));
            }
            lu.solve_in_place(&mut f);
        }
        for i in 0..n {
            f[i] = (f[i] - self.s.zn.zn[1][i]) / hg;
        }
        Ok(wrms_norm(&f, &self.w.ewt))
    }

    /// Value (`derivative = 0`) or `k`-th derivative at `t` inside the last step.
    pub fn interpolate(&self, t: f64, derivative: usize, out: &mut [f64]) -> Result<(), BdfError> {
        let s = &self.s;
        if out.len() != s.n {
            return Err(BdfError::InvalidInput {
                field: "out",
                message: format!("has {} entries, the problem has {} states", out.len(), s.n),
            });
        }
        if derivative > 5 {
            return Err(BdfError::InvalidInput {
                field: "derivative",
                message: format!("must be <= 5, got {derivative}"),
            });
        }
        let tfuzz = 100.0 * f64::EPSILON * (s.tn.abs() + s.hu.abs());
        let t_lo = s.tn - s.hu - tfuzz;
        let t_hi = s.tn + tfuzz;
        if !(t >= t_lo && t <= t_hi) {
            return Err(BdfError::BadInterpolationTime {
                t,
                t_lo: s.tn - s.hu,
                t_hi: s.tn,
            });
        }
        if s.pending_h0 {
            // No step yet: zn[1] holds y' itself.
            out.iter_mut().for_each(|v| *v = 0.0);
            match derivative {
                0 => out.copy_from_slice(&s.zn.zn[0]),
                1 => out.copy_from_slice(&s.zn.zn[1]),
                _ => {}
            }
            return Ok(());
        }
        let sfrac = (t - s.tn) / s.h;
        s.zn.derivative(s.q, sfrac, s.h, derivative, out);
        Ok(())
    }

    /// One internal step (CVODE's cvStep). On error the state of the last step is kept.
    pub(super) fn step<P: OdeProblem>(&mut self, problem: &mut P) -> Result<(), BdfError> {
        let saved_t = self.s.tn;
        let mut ncf = 0usize;
        let mut nef = 0usize;
        let mut flag = StepFlag::FirstCall;
        // hprime always describes the next step (also before the first step and after a failed
        // first step), so a pending change is applied whenever it differs.
        if self.s.hprime != self.s.h {
            self.adjust_params();
        }
        self.apply_stability_cap();
        let dsm = loop {
            self.predict();
            self.set_coefficients();
            let outcome = self.nonlinear_solve(problem, flag);
            match outcome {
                NlsOutcome::Converged => {}
                other => {
                    self.handle_nls_failure(other, saved_t, &mut ncf)?;
                    flag = StepFlag::PrevConvFail;
                    continue;
                }
            }
            if self.s.fixed {
                break 0.0;
            }
            let dsm = self.s.acnrm * self.s.tq[2];
            if dsm <= 1.0 {
                break dsm;
            }
            self.handle_error_test_failure(problem, dsm, saved_t, &mut nef)?;
            flag = StepFlag::PrevErrFail;
        };
        self.complete_step();
        if !self.s.fixed {
            self.prepare_next_step(dsm);
            self.s.etamax = if self.s.nst <= SMALL_NST {
                ETAMX2
            } else {
                ETAMX3
            };
        } else {
            self.s.hprime = self.s.h;
            self.s.qprime = self.s.q;
            self.s.eta = 1.0;
        }
        let tq2 = self.s.tq[2];
        self.s.acor.iter_mut().for_each(|v| *v *= tq2);
        let st = &mut self.s.stats;
        st.order = self.s.q;
        st.h = self.s.h;
        st.h_next = self.s.hprime;
        st.order_next = self.s.qprime;
        Ok(())
    }

    /// Applies a pending order change and the step ratio `eta` (cvAdjustParams).
    pub(super) fn adjust_params(&mut self) {
        let s = &mut self.s;
        if s.qprime != s.q {
            if s.qprime > s.q {
                let saved = s.zn.zn.len() - 1;
                s.zn.increase_order(s.q, s.hscale, &s.tau, saved);
            } else {
                s.zn.decrease_order(s.q, s.hscale, &s.tau);
            }
            s.q = s.qprime;
            s.qwait = s.q + 1;
        }
        self.rescale();
    }

    /// Scales the history to the step `eta * hscale` (cvRescale).
    pub(super) fn rescale(&mut self) {
        let s = &mut self.s;
        s.zn.rescale(s.q, s.eta);
        s.h = s.hscale * s.eta;
        s.hprime = s.h;
        s.hscale = s.h;
        s.nscon = 0;
    }

    /// Advances time and predicts the history; lands exactly on the stop time when the step
    /// was sized to reach it.
    fn predict(&mut self) {
        let s = &mut self.s;
        let t_new = s.tn + s.h;
        let landing = s.tstop.is_finite()
            && ((t_new - s.tstop).abs() <= 4.0 * f64::EPSILON * s.tstop.abs().max(s.h.abs())
                || t_new > s.tstop);
        s.tn = if landing { s.tstop } else { t_new };
        s.zn.predict(s.q);
    }

    /// Corrector coefficients, gamma and its ratio to the last setup (cvSet).
    fn set_coefficients(&mut self) {
        let s = &mut self.s;
        let c = bdf_coefficients(s.q, s.h, &s.tau, NLS_COEF, s.qwait == 1, &s.tq);
        s.l = c.l;
        s.tq = c.tq;
        s.rl1 = 1.0 / s.l[1];
        s.gamma = s.h * s.rl1;
        if s.nst == 0 {
            s.gammap = s.gamma;
        }
        s.gamrat = if s.nst > 0 { s.gamma / s.gammap } else { 1.0 };
    }

    /// Undoes the prediction after a failed attempt (cvRestore).
    fn restore_history(&mut self, saved_t: f64) {
        self.s.tn = saved_t;
        self.s.zn.restore(self.s.q);
    }

    /// Nonlinear solver failure: shrink the step or give up (cvHandleNFlag).
    fn handle_nls_failure(
        &mut self,
        outcome: NlsOutcome,
        saved_t: f64,
        ncf: &mut usize,
    ) -> Result<(), BdfError> {
        self.s.stats.conv_fails += 1;
        self.restore_history(saved_t);
        let t = self.s.tn;
        let h = self.s.h;
        if let NlsOutcome::Fatal(message) = outcome {
            return Err(BdfError::ProblemFailed { t, message });
        }
        *ncf += 1;
        self.s.etamax = 1.0;
        let at_hmin = h.abs() <= self.s.opts.h_min * ONEPSM;
        if at_hmin || *ncf >= self.s.opts.max_conv_fails || self.s.fixed {
            return Err(match outcome {
                NlsOutcome::RhsRecoverable(ProblemError::NonFinite) => BdfError::NonFiniteRhs { t },
                NlsOutcome::RhsRecoverable(e) => BdfError::RepeatedProblemError {
                    t,
                    message: problem_error(e),
                },
                _ if at_hmin => BdfError::StepSizeUnderflow { t, h },
                _ => BdfError::TooManyConvergenceFailures {
                    t,
                    h,
                    failures: *ncf,
                },
            });
        }
        self.s.eta = ETACF.max(self.s.opts.h_min / h.abs());
        self.rescale();
        // When the step has shrunk to nothing because the problem keeps failing, name the cause.
        self.check_step_size().map_err(|e| match outcome {
            NlsOutcome::RhsRecoverable(ProblemError::NonFinite) => BdfError::NonFiniteRhs { t },
            NlsOutcome::RhsRecoverable(p) => BdfError::RepeatedProblemError {
                t,
                message: problem_error(p),
            },
            _ => e,
        })
    }

    /// The step must still move time forward.
    fn check_step_size(&self) -> Result<(), BdfError> {
        let s = &self.s;
        if s.tn + s.h == s.tn || s.h <= 0.0 || !s.h.is_finite() {
            return Err(BdfError::StepSizeUnderflow { t: s.tn, h: s.h });
        }
        Ok(())
    }

    /// Local error test failed: shrink the step, lower the order, or reload at order 1
    /// (cvDoErrorTest).
    ///
    /// Long on purpose: CVODE's cvDoErrorTest in one piece, kept parallel to it line by line.
    fn handle_error_test_failure<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        dsm: f64,
        saved_t: f64,
        nef: &mut usize,
    ) -> Result<(), BdfError> {
        *nef += 1;
        self.s.stats.err_test_fails += 1;
        let q_failed = self.s.q;
        let h_failed = self.s.h;
        self.restore_history(saved_t);
        let s = &mut self.s;
        if s.h.abs() <= s.opts.h_min * ONEPSM || *nef >= s.opts.max_err_test_fails {
            return Err(BdfError::TooManyErrorTestFailures {
                t: s.tn,
                h: s.h,
                failures: *nef,
            });
        }
        s.etamax = 1.0;
        if s.opts.stability_limit_detection {
            let (nst, t) = (s.nst, s.tn);
            s.stability
                .record_error_test_failure(nst, t, q_failed, h_failed);
        }
        if *nef <= MXNEF1 {
            let mut eta = 1.0 / ((BIAS2 * dsm).powf(1.0 / (s.q + 1) as f64) + ADDON);
            eta = ETAMIN.max(eta.max(s.opts.h_min / s.h.abs()));
            if *nef >= SMALL_NEF {
                eta = eta.min(ETAMXF);
            }
            s.eta = eta;
            self.rescale();
            return self.check_step_size();
        }
        if s.q > 1 {
            s.eta = ETAMIN.max(s.opts.h_min / s.h.abs());
            s.zn.decrease_order(s.q, s.hscale, &s.tau);
            s.q -= 1;
            s.qwait = s.q + 1;
            self.rescale();
            return self.check_step_size();
        }
        // Already at order 1: reload y' from scratch.
        s.eta = ETAMIN.max(s.opts.h_min / s.h.abs());
        s.h *= s.eta;
        s.hprime = s.h;
        s.hscale = s.h;
        s.qwait = LONG_WAIT;
        s.nscon = 0;
        let t = s.tn;
        let y = s.zn.zn[0].clone();
        let mut f = vec![0.0; s.n];
        eval_rhs(problem, &mut self.s.stats, t, &y, &mut f).map_err(|e| match e {
            ProblemError::NonFinite => BdfError::NonFiniteRhs { t },
            other => BdfError::ProblemFailed {
                t,
                message: problem_error(other),
            },
        })?;
        if self.has_mass {
            let mut lu = DenseLu::new(self.s.n);
            eval_mass(problem, self.constant_mass.as_ref(), t, &y, lu.matrix_mut()).map_err(
                |e| BdfError::ProblemFailed {
                    t,
                    message: format!("mass matrix: {}", problem_error(e)),
                },
            )?;
            if !lu.factor() {
                return Err(BdfError::ProblemFailed {
                    t,
                    message: "the mass matrix is singular".to_string(),
                });
            }
            lu.solve_in_place(&mut f);
        }
        let h = self.s.h;
        for (z, fv) in self.s.zn.zn[1].iter_mut().zip(&f) {
            *z = h * fv;
        }
        self.check_step_size()
    }

    /// Accepts the step: corrects the history and shifts the step-size record (cvCompleteStep).
    fn complete_step(&mut self) {
        let s = &mut self.s;
        s.nst += 1;
        s.nscon += 1;
        s.stats.steps += 1;
        s.hu = s.h;
        for i in (2..=s.q).rev() {
            s.tau[i] = s.tau[i - 1];
        }
        if s.q == 1 && s.nst > 1 {
            s.tau[2] = s.tau[1];
        }
        s.tau[1] = s.h;
        s.zn.correct(s.q, &s.l, &s.acor);
        s.qwait = s.qwait.saturating_sub(1);
        let qmax = s.zn.zn.len() - 1;
        if s.qwait == 1 && s.q != qmax {
            let (_, hi) = s.zn.zn.split_at_mut(qmax);
            hi[0].copy_from_slice(&s.acor);
            s.saved_tq5 = s.tq[5];
        }
        let (nst, t) = (s.nst, s.tn);
        s.stability.on_step_accepted(nst, t);
    }

    /// Chooses the next step size and order (cvPrepareNextStep, cvChooseEta, cvSetEta).
    ///
    /// Long on purpose: CVODE's cvPrepareNextStep/cvChooseEta/cvSetEta in one piece, kept parallel to them.
    fn prepare_next_step(&mut self, dsm: f64) {
        let qmax = self.s.zn.zn.len() - 1;
        let landed = if self.s.tn == self.s.tstop {
            self.s.h_unclipped.take()
        } else {
            None
        };
        let s = &mut self.s;
        if s.etamax == 1.0 {
            s.qwait = s.qwait.max(2);
            s.qprime = s.q;
            s.hprime = s.h;
            s.eta = 1.0;
            return;
        }
        let big_l = (s.q + 1) as f64;
        let etaq = 1.0 / ((BIAS2 * dsm).powf(1.0 / big_l) + ADDON);
        if s.qwait != 0 {
            s.eta = etaq;
            s.qprime = s.q;
        } else {
            s.qwait = 2;
            let etaqm1 = if s.q > 1 {
                let ddn = wrms_norm(&s.zn.zn[s.q], &self.w.ewt) * s.tq[1];
                1.0 / ((BIAS1 * ddn).powf(1.0 / s.q as f64) + ADDON)
            } else {
                0.0
            };
            let etaqp1 = if s.q != qmax && s.saved_tq5 != 0.0 {
                let cquot = (s.tq[5] / s.saved_tq5) * (s.h / s.tau[2]).powi(s.q as i32 + 1);
                for ((t, z), a) in self.w.tempv.iter_mut().zip(&s.zn.zn[qmax]).zip(&s.acor) {
                    *t = a - cquot * z;
                }
                let dup = wrms_norm(&self.w.tempv, &self.w.ewt) * s.tq[3];
                1.0 / ((BIAS3 * dup).powf(1.0 / (big_l + 1.0)) + ADDON)
            } else {
                0.0
            };
            let cap = s.stability.order_cap(s.nst, qmax);
            let etaqp1 = if s.q + 1 > cap { 0.0 } else { etaqp1 };
            let etam = etaqm1.max(etaq).max(etaqp1);
            if etam < THRESH {
                s.eta = 1.0;
                s.qprime = s.q;
            } else if etam == etaq {
                s.eta = etaq;
                s.qprime = s.q;
            } else if etam == etaqm1 {
                s.eta = etaqm1;
                s.qprime = s.q - 1;
            } else {
                s.eta = etaqp1;
                s.qprime = s.q + 1;
                let (_, hi) = s.zn.zn.split_at_mut(qmax);
                hi[0].copy_from_slice(&s.acor);
            }
        }
        // cvSetEta, with the growth limit measured from the step the controller wanted before
        // it was shortened to land on a stop time.
        let etamax = match landed {
            Some(hu) if hu > s.h => s.etamax.max(hu / s.h),
            _ => s.etamax,
        };
        let eta_threshold_ok = match landed {
            // A landing step is not a step the controller chose: return to the wanted size even
            // when the change is small.
            Some(hu) if hu > s.h => s.eta > 1.0,
            _ => s.eta >= THRESH,
        };
        if !eta_threshold_ok {
            s.eta = 1.0;
            s.hprime = s.h;
        } else {
            s.eta = s.eta.min(etamax);
            s.eta /= (s.h.abs() * s.eta / s.opts.h_max).max(1.0);
            s.hprime = s.h * s.eta;
            if s.qprime < s.q {
                s.nscon = 0;
            }
        }
    }

    /// Forces the order down when stability-limit detection holds it (one order per step).
    fn apply_stability_cap(&mut self) {
        if !self.s.opts.stability_limit_detection || self.s.fixed {
            return;
        }
        let qmax = self.s.zn.zn.len() - 1;
        let cap = self.s.stability.order_cap(self.s.nst, qmax);
        if self.s.q > cap {
            let s = &mut self.s;
            s.zn.decrease_order(s.q, s.hscale, &s.tau);
            s.q -= 1;
            s.qprime = s.q;
            s.qwait = s.q + 1;
            s.stats.stability_order_reductions += 1;
        }
    }
}
