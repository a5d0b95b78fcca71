//! The Jacobian `df/dy`: analytic from the problem or by forward differences (CVODE's
//! cvLsDenseDQJac increments), optionally with column grouping from a sparsity pattern.

use faer::Mat;

use super::pattern::JacobianPattern;
use super::problem::{OdeProblem, ProblemError};

/// Evaluation context for a finite-difference Jacobian at `(t, y)` with `fy = f(t, y)`.
pub struct DifferenceQuotient<'a> {
    pub t: f64,
    pub h: f64,
    pub y: &'a [f64],
    pub fy: &'a [f64],
    pub ewt: &'a [f64],
}

/// Forms `df/dy` by forward differences into `jac`; returns the number of RHS evaluations.
/// Increments follow CVODE: `max(sqrt(eps) |y_j|, min_inc / ewt_j)`.
pub fn finite_difference_jacobian<P: OdeProblem + ?Sized>(
    problem: &mut P,
    at: &DifferenceQuotient<'_>,
    groups: Option<(&JacobianPattern, &[Vec<usize>])>,
    jac: &mut Mat<f64>,
    work_y: &mut [f64],
    work_f: &mut [f64],
) -> Result<u64, ProblemError> {
    let n = at.y.len();
    let srur = f64::EPSILON.sqrt();
    let fnorm = super::nordsieck::wrms_norm(at.fy, at.ewt);
    let min_inc = if fnorm != 0.0 {
        1000.0 * at.h.abs() * f64::EPSILON * n as f64 * fnorm
    } else {
        1.0
    };
    let increment = |j: usize| (srur * at.y[j].abs()).max(min_inc / at.ewt[j]);
    work_y.copy_from_slice(at.y);
    let mut evals = 0;
    match groups {
        None => {
            for j in 0..n {
                let yj = at.y[j];
                work_y[j] = yj + increment(j);
                let inc = work_y[j] - yj;
                problem.rhs(at.t, work_y, work_f)?;
                evals += 1;
                check_finite(work_f)?;
                work_y[j] = yj;
                let col = jac.col_as_slice_mut(j);
                for ((c, fp), f0) in col.iter_mut().zip(work_f.iter()).zip(at.fy) {
                    *c = (fp - f0) / inc;
                }
            }
        }
        Some((pattern, groups)) => {
            jac.fill(0.0);
            for group in groups {
                for &j in group {
                    work_y[j] = at.y[j] + increment(j);
                }
                problem.rhs(at.t, work_y, work_f)?;
                evals += 1;
                check_finite(work_f)?;
                for &j in group {
                    let inc = work_y[j] - at.y[j];
                    work_y[j] = at.y[j];
                    let col = jac.col_as_slice_mut(j);
                    for &i in pattern.rows(j) {
                        col[i] = (work_f[i] - at.fy[i]) / inc;
                    }
                }
            }
        }
    }
    Ok(evals)
}

fn check_finite(v: &[f64]) -> Result<(), ProblemError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ProblemError::NonFinite)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::MatMut;

    /// f_i = sin(y_i) * y_{i+1} + y_{i-1}^2 : tridiagonal Jacobian, known analytically.
    struct Tridiag(usize);
    impl OdeProblem for Tridiag {
        fn dim(&self) -> usize {
            self.0
        }
        fn rhs(&mut self, _t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
            let n = self.0;
            for i in 0..n {
                let right = if i + 1 < n { y[i + 1] } else { 1.0 };
                let left = if i > 0 { y[i - 1] * y[i - 1] } else { 0.0 };
                f[i] = y[i].sin() * right + left;
            }
            Ok(())
        }
        fn jacobian(
            &mut self,
            _t: f64,
            _y: &[f64],
            _j: MatMut<'_, f64>,
        ) -> Result<bool, ProblemError> {
            Ok(false)
        }
    }

    fn exact(y: &[f64]) -> Mat<f64> {
        let n = y.len();
        let mut j = Mat::zeros(n, n);
        for i in 0..n {
            let right = if i + 1 < n { y[i + 1] } else { 1.0 };
            j[(i, i)] = y[i].cos() * right;
            if i + 1 < n {
                j[(i, i + 1)] = y[i].sin();
            }
            if i > 0 {
                j[(i, i - 1)] = 2.0 * y[i - 1];
            }
        }
        j
    }

    #[test]
    fn grouped_and_plain_differences_match_analytic_jacobian() {
        let n = 9;
        let mut p = Tridiag(n);
        let y: Vec<f64> = (0..n).map(|i| 0.3 + 0.1 * i as f64).collect();
        let mut fy = vec![0.0; n];
        p.rhs(0.0, &y, &mut fy).unwrap();
        let ewt = vec![1e6; n];
        let at = DifferenceQuotient {
            t: 0.0,
            h: 1e-3,
            y: &y,
            fy: &fy,
            ewt: &ewt,
        };
        let cols: Vec<Vec<usize>> = (0..n)
            .map(|j| (j.saturating_sub(1)..(j + 2).min(n)).collect())
            .collect();
        let pattern = JacobianPattern::from_columns(n, &cols).unwrap();
        let groups = pattern.column_groups();
        assert_eq!(
            groups.len(),
            3,
            "a tridiagonal pattern needs exactly three colours"
        );
        let reference = exact(&y);
        let (mut wy, mut wf) = (vec![0.0; n], vec![0.0; n]);
        for grouping in [None, Some((&pattern, groups.as_slice()))] {
            let mut jac = Mat::zeros(n, n);
            let evals =
                finite_difference_jacobian(&mut p, &at, grouping, &mut jac, &mut wy, &mut wf)
                    .unwrap();
            assert_eq!(evals, if grouping.is_some() { 3 } else { n as u64 });
            for i in 0..n {
                for j in 0..n {
                    assert!((jac[(i, j)] - reference[(i, j)]).abs() < 1e-6, "({i},{j})");
                }
            }
        }
    }

    #[test]
    fn pattern_rejects_out_of_range_rows() {
        let err = JacobianPattern::from_columns(2, &[vec![0], vec![5]]).unwrap_err();
        assert!(format!("{err}").contains("column 1 names row 5"));
    }
}
