//! Finite-difference Jacobians with column grouping, and state-dependent mass matrices, checked
//! against closed-form solutions.

use engine_mount_chassis::ode::{
    Bdf, BdfOptions, JacobianPattern, OdeProblem, ProblemError, Tolerance,
};
use faer::MatMut;
use std::f64::consts::PI;

/// Semi-discrete heat equation u_t = u_xx on (0, pi), u = 0 at both ends, n interior points.
/// With u(0) = sin(x_j) the exact solution is exp(lambda t) sin(x_j),
/// lambda = -(4 / dx^2) sin^2(dx / 2): the sine is an eigenvector of the discrete Laplacian.
struct Heat {
    n: usize,
    with_pattern: bool,
}

impl Heat {
    fn dx(&self) -> f64 {
        PI / (self.n + 1) as f64
    }
    fn lambda(&self) -> f64 {
        let dx = self.dx();
        -(4.0 / (dx * dx)) * (dx / 2.0).sin().powi(2)
    }
}

impl OdeProblem for Heat {
    fn dim(&self) -> usize {
        self.n
    }
    fn rhs(&mut self, _t: f64, u: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        let inv = 1.0 / (self.dx() * self.dx());
        for i in 0..self.n {
            let left = if i > 0 { u[i - 1] } else { 0.0 };
            let right = if i + 1 < self.n { u[i + 1] } else { 0.0 };
            f[i] = (left - 2.0 * u[i] + right) * inv;
        }
        Ok(())
    }
    fn jacobian_pattern(&self) -> Option<JacobianPattern> {
        if !self.with_pattern {
            return None;
        }
        let cols: Vec<Vec<usize>> = (0..self.n)
            .map(|j| (j.saturating_sub(1)..(j + 2).min(self.n)).collect())
            .collect();
        JacobianPattern::from_columns(self.n, &cols).ok()
    }
}

fn heat_run(with_pattern: bool) -> (f64, u64, u64) {
    let mut p = Heat {
        n: 60,
        with_pattern,
    };
    let dx = p.dx();
    let u0: Vec<f64> = (1..=p.n).map(|j| (j as f64 * dx).sin()).collect();
    let opts = BdfOptions {
        rtol: 1e-7,
        atol: Tolerance::Scalar(1e-10),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &u0, opts).unwrap();
    bdf.advance_to(&mut p, 1.0).unwrap();
    let decay = p.lambda().exp();
    let err = bdf
        .y()
        .iter()
        .zip(&u0)
        .map(|(u, s)| (u - decay * s).abs())
        .fold(0.0, f64::max);
    let st = bdf.stats();
    (err / decay, st.rhs_evals_jac, st.jac_evals)
}

#[test]
fn grouped_finite_differences_solve_the_heat_equation() {
    let (err_plain, fd_plain, jac_plain) = heat_run(false);
    let (err_grouped, fd_grouped, jac_grouped) = heat_run(true);
    eprintln!("plain: err {err_plain:.2e}, {fd_plain} FD evals; grouped: err {err_grouped:.2e}, {fd_grouped} FD evals");
    assert!(err_plain < 1e-5 && err_grouped < 1e-5);
    // A tridiagonal pattern needs three evaluations per Jacobian instead of n = 60.
    assert_eq!(fd_plain, 60 * jac_plain);
    assert_eq!(fd_grouped, 3 * jac_grouped);
}

/// (1 + y_i^2) y_i' = -(1 + y_i^2) y_i: state-dependent mass matrix, exact y = y0 exp(-t).
struct StateMass;
impl OdeProblem for StateMass {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        for i in 0..2 {
            f[i] = -(1.0 + y[i] * y[i]) * y[i];
        }
        Ok(())
    }
    fn has_mass_matrix(&self) -> bool {
        true
    }
    fn mass(&mut self, _t: f64, y: &[f64], mut m: MatMut<'_, f64>) -> Result<(), ProblemError> {
        for i in 0..2 {
            m[(i, i)] = 1.0 + y[i] * y[i];
        }
        Ok(())
    }
}

#[test]
fn state_dependent_mass_matrix_is_honoured() {
    let mut p = StateMass;
    let y0 = [2.0, -0.5];
    let opts = BdfOptions {
        rtol: 1e-8,
        atol: Tolerance::Scalar(1e-10),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, opts).unwrap();
    bdf.advance_to(&mut p, 2.0).unwrap();
    for (i, (y, y_start)) in bdf.y().iter().zip(y0).enumerate() {
        let exact = y_start * (-2.0_f64).exp();
        assert!((y - exact).abs() < 1e-6, "component {i}: {y} vs {exact}");
    }
}
