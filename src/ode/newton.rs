//! Modified Newton iteration for the BDF corrector with reuse of the iteration matrix
//! `M - gamma J` and of the Jacobian by CVODE's rules (cvNls, SUNNonlinSol_Newton, cvLsSetup).
//!
//! Unknown: the correction `acor` to the predicted state. Residual
//! `G(acor) = M (rl1 zn[1] + acor) - gamma f(t, zn[0] + acor)`.

use super::bdf::{Bdf, NlsOutcome, StepFlag};
use super::evaluation::{eval_mass, eval_rhs};
use super::jacobian::{finite_difference_jacobian, DifferenceQuotient};
use super::linear_solver::IterationMatrix;
use super::nordsieck::wrms_norm;
use super::problem::{OdeProblem, ProblemError};

/// Refactor after this many steps with the same iteration matrix (CVODE msbp).
const MSBP: u64 = 20;
/// Refactor when gamma changed by more than this fraction (CVODE dgmax_lsetup).
const DGMAX_LSETUP: f64 = 0.3;
/// A stale Jacobian is re-evaluated after a convergence failure only if gamma changed by less
/// than this fraction (CVLS_DGMAX).
const DGMAX_JBAD: f64 = 0.2;
/// Convergence-rate decay (CVODE CRDOWN).
const CRDOWN: f64 = 0.3;
/// Divergence ratio (CVODE RDIV).
const RDIV: f64 = 2.0;
/// Newton iterations per attempt (CVODE NLS_MAXCOR).
const MAX_ITERS: usize = 3;

/// Why the iteration matrix is being rebuilt (CVODE's convfail argument of lsetup).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ConvFail {
    None,
    Other,
    BadJacobian,
}

fn recoverable(e: ProblemError) -> NlsOutcome {
    match e {
        ProblemError::Fatal(m) => NlsOutcome::Fatal(m),
        other => NlsOutcome::RhsRecoverable(other),
    }
}

impl Bdf {
    /// Solves the corrector equation for the current step attempt; on success `acor` holds the
    /// correction and `acnrm` its WRMS norm.
    pub(super) fn nonlinear_solve<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        flag: StepFlag,
    ) -> NlsOutcome {
        let mut convfail = if matches!(flag, StepFlag::FirstCall | StepFlag::PrevErrFail) {
            ConvFail::None
        } else {
            ConvFail::Other
        };
        let s = &self.s;
        let mut call_setup = flag != StepFlag::FirstCall
            || s.nst == 0
            || s.nst >= s.nstlp + MSBP
            || (s.gamrat - 1.0).abs() > DGMAX_LSETUP
            || !s.lin.matrix.is_factored();
        self.s.acor.iter_mut().for_each(|v| *v = 0.0);
        let mut jcur = false;
        loop {
            if let Err(e) = self.residual(problem) {
                return recoverable(e);
            }
            if call_setup {
                match self.setup(problem, convfail) {
                    Ok(j) => jcur = j,
                    Err(NlsOutcome::ConvergenceFailure) if !jcur => {
                        // Singular matrix with a stale Jacobian: try a fresh one.
                        convfail = ConvFail::BadJacobian;
                        jcur = true;
                        continue;
                    }
                    Err(other) => return other,
                }
            }
            match self.newton_iterations(problem) {
                NlsOutcome::ConvergenceFailure if !jcur => {
                    call_setup = true;
                    convfail = ConvFail::BadJacobian;
                    self.s.acor.iter_mut().for_each(|v| *v = 0.0);
                }
                other => return other,
            }
        }
    }

    /// Newton iterations with the current iteration matrix; `delta` holds the residual on entry.
    fn newton_iterations<P: OdeProblem>(&mut self, problem: &mut P) -> NlsOutcome {
        let mut m = 0usize;
        loop {
            self.s.stats.newton_iters += 1;
            for d in self.w.delta.iter_mut() {
                *d = -*d;
            }
            self.s.lin.matrix.solve_in_place(&mut self.w.delta);
            if self.s.gamrat != 1.0 {
                let scale = 2.0 / (1.0 + self.s.gamrat);
                self.w.delta.iter_mut().for_each(|d| *d *= scale);
            }
            for (a, d) in self.s.acor.iter_mut().zip(&self.w.delta) {
                *a += d;
            }
            let del = wrms_norm(&self.w.delta, &self.w.ewt);
            if !del.is_finite() {
                return NlsOutcome::ConvergenceFailure;
            }
            if m > 0 {
                self.s.crate_ = (CRDOWN * self.s.crate_).max(del / self.s.delp);
            }
            let dcon = del * self.s.crate_.min(1.0) / self.s.tq[4];
            if dcon <= 1.0 {
                self.s.acnrm = if m == 0 {
                    del
                } else {
                    wrms_norm(&self.s.acor, &self.w.ewt)
                };
                // The state at the accepted iterate.
                for ((y, z), a) in self.w.y.iter_mut().zip(&self.s.zn.zn[0]).zip(&self.s.acor) {
                    *y = z + a;
                }
                return NlsOutcome::Converged;
            }
            if m >= 1 && del > RDIV * self.s.delp {
                return NlsOutcome::ConvergenceFailure;
            }
            self.s.delp = del;
            m += 1;
            if m >= MAX_ITERS {
                return NlsOutcome::ConvergenceFailure;
            }
            if let Err(e) = self.residual(problem) {
                return recoverable(e);
            }
        }
    }

    /// `delta = M (rl1 zn[1] + acor) - gamma f(tn, zn[0] + acor)`; leaves `y` and `ftemp` at the
    /// iterate.
    fn residual<P: OdeProblem>(&mut self, problem: &mut P) -> Result<(), ProblemError> {
        let s = &mut self.s;
        let w = &mut self.w;
        for ((y, z), a) in w.y.iter_mut().zip(&s.zn.zn[0]).zip(&s.acor) {
            *y = z + a;
        }
        eval_rhs(problem, &mut s.stats, s.tn, &w.y, &mut w.ftemp)?;
        let rl1 = s.rl1;
        let gamma = s.gamma;
        if self.has_mass {
            for ((t, z), a) in w.tempv.iter_mut().zip(&s.zn.zn[1]).zip(&s.acor) {
                *t = rl1 * z + a;
            }
            eval_mass(
                problem,
                self.constant_mass.as_ref(),
                s.tn,
                &w.y,
                &mut w.mass,
            )?;
            for (d, f) in w.delta.iter_mut().zip(&w.ftemp) {
                *d = -gamma * f;
            }
            for (j, tj) in w.tempv.iter().enumerate() {
                let col = w.mass.col_as_slice(j);
                for (d, mij) in w.delta.iter_mut().zip(col) {
                    *d += mij * tj;
                }
            }
        } else {
            for (((d, z), a), f) in w
                .delta
                .iter_mut()
                .zip(&s.zn.zn[1])
                .zip(&s.acor)
                .zip(&w.ftemp)
            {
                *d = rl1 * z + a - gamma * f;
            }
        }
        Ok(())
    }

    /// Builds and factorises `M - gamma J`, re-evaluating `J` when it is judged stale (cvLsSetup).
    /// Returns whether the Jacobian is fresh.
    ///
    /// Long on purpose: CVODE's cvLsSetup in one piece (Jacobian age, evaluation, factorisation, structured or dense), kept parallel to it.
    fn setup<P: OdeProblem>(
        &mut self,
        problem: &mut P,
        convfail: ConvFail,
    ) -> Result<bool, NlsOutcome> {
        let s = &mut self.s;
        let w = &mut self.w;
        let dgamma = (s.gamma / s.gammap - 1.0).abs();
        let jbad = s.nst == 0
            || s.nst >= s.lin.nstlj + s.opts.jacobian_max_age
            || (convfail == ConvFail::BadJacobian && dgamma < DGMAX_JBAD)
            || convfail == ConvFail::Other;
        let jcur = jbad;
        if jbad {
            s.stats.jac_evals += 1;
            s.lin.nstlj = s.nst;
            match &mut s.lin.matrix {
                IterationMatrix::Dense { saved_j, .. } => {
                    saved_j.fill(0.0);
                    let analytic = problem
                        .jacobian(s.tn, &w.y, saved_j.as_mut())
                        .map_err(recoverable)?;
                    if analytic {
                        if saved_j.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
                            return Err(NlsOutcome::RhsRecoverable(ProblemError::NonFinite));
                        }
                    } else {
                        let at = DifferenceQuotient {
                            t: s.tn,
                            h: s.h,
                            y: &w.y,
                            fy: &w.ftemp,
                            ewt: &w.ewt,
                        };
                        let groups = self.pattern.as_ref().map(|(p, g)| (p, g.as_slice()));
                        let evals = finite_difference_jacobian(
                            problem,
                            &at,
                            groups,
                            saved_j,
                            &mut w.jac_y,
                            &mut w.jac_f,
                        )
                        .map_err(recoverable)?;
                        s.stats.rhs_evals += evals;
                        s.stats.rhs_evals_jac += evals;
                    }
                }
                IterationMatrix::BlockLowRank { saved_j, .. } => {
                    saved_j.clear();
                    problem
                        .structured_jacobian(s.tn, &w.y, saved_j)
                        .map_err(recoverable)?;
                    if !saved_j.is_finite() {
                        return Err(NlsOutcome::RhsRecoverable(ProblemError::NonFinite));
                    }
                }
            }
        }
        let gamma = s.gamma;
        let n = s.n;
        if self.has_mass {
            eval_mass(
                problem,
                self.constant_mass.as_ref(),
                s.tn,
                &w.y,
                &mut w.mass,
            )
            .map_err(recoverable)?;
        }
        let ok = match &mut s.lin.matrix {
            IterationMatrix::Dense { saved_j, lu } => {
                let a = lu.matrix_mut();
                for j in 0..n {
                    let jc = saved_j.col_as_slice(j);
                    let ac = a.col_as_slice_mut(j);
                    for (x, jv) in ac.iter_mut().zip(jc) {
                        *x = -gamma * jv;
                    }
                    if self.has_mass {
                        for (x, mv) in ac.iter_mut().zip(w.mass.col_as_slice(j)) {
                            *x += mv;
                        }
                    } else {
                        ac[j] += 1.0;
                    }
                }
                lu.factor()
            }
            IterationMatrix::BlockLowRank { saved_j, lu } => lu.factor(saved_j, gamma),
        };
        s.stats.factorizations += 1;
        s.gamrat = 1.0;
        s.gammap = s.gamma;
        s.crate_ = 1.0;
        s.nstlp = s.nst;
        if ok {
            Ok(jcur)
        } else {
            Err(NlsOutcome::ConvergenceFailure)
        }
    }
}
