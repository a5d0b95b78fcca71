//! Problems with known solutions, shipped with the solver for tests and benchmarks.

use std::f64::consts::PI;

use faer::{Mat, MatMut, Side};

use super::block_low_rank::{BlockLowRankJacobian, BlockLowRankShape};
use super::problem::{OdeProblem, ProblemError};

/// `y' = A y` with `A` in real Jordan form: a decaying oscillation `lambda = a ± i b` in
/// (y0, y1) and a decay `c` in y2. Every derivative is known in closed form.
#[derive(Debug, Clone)]
pub struct LinearOscillator {
    /// Real part of the oscillation's eigenvalue pair (negative: decaying).
    pub a: f64,
    /// Imaginary part of the oscillation's eigenvalue pair (rad/s).
    pub b: f64,
    /// Decay rate of the third component (negative: decaying).
    pub c: f64,
    /// Initial state.
    pub y0: [f64; 3],
}

impl Default for LinearOscillator {
    fn default() -> Self {
        Self {
            a: -0.5,
            b: 2.0,
            c: -3.0,
            y0: [1.0, 0.5, 2.0],
        }
    }
}

impl LinearOscillator {
    /// The `k`-th time derivative of the exact solution at `t`.
    pub fn exact_derivative(&self, t: f64, k: usize) -> [f64; 3] {
        // (y0 + i y1)(t) = z0 exp(lambda t), d^k/dt^k multiplies by lambda^k.
        let (mut pr, mut pi) = (1.0, 0.0);
        for _ in 0..k {
            let (r, i) = (pr * self.a - pi * self.b, pr * self.b + pi * self.a);
            pr = r;
            pi = i;
        }
        let e = (self.a * t).exp();
        let (cr, ci) = (e * (self.b * t).cos(), e * (self.b * t).sin());
        let (zr, zi) = (self.y0[0], self.y0[1]);
        // z0 * lambda^k * exp(i b t) * exp(a t)
        let (wr, wi) = (zr * pr - zi * pi, zr * pi + zi * pr);
        [
            wr * cr - wi * ci,
            wr * ci + wi * cr,
            self.y0[2] * self.c.powi(k as i32) * (self.c * t).exp(),
        ]
    }
}

impl OdeProblem for LinearOscillator {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&mut self, _t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        f[0] = self.a * y[0] - self.b * y[1];
        f[1] = self.b * y[0] + self.a * y[1];
        f[2] = self.c * y[2];
        Ok(())
    }
    fn jacobian(
        &mut self,
        _t: f64,
        _y: &[f64],
        mut j: MatMut<'_, f64>,
    ) -> Result<bool, ProblemError> {
        j[(0, 0)] = self.a;
        j[(0, 1)] = -self.b;
        j[(1, 0)] = self.b;
        j[(1, 1)] = self.a;
        j[(2, 2)] = self.c;
        Ok(true)
    }
}

/// Robertson's chemical kinetics (stiff, nonlinear). `analytic_jacobian = false` makes the
/// integrator use finite differences.
#[derive(Debug, Clone)]
pub struct Robertson {
    /// Whether [`OdeProblem::jacobian`] supplies the exact Jacobian.
    pub analytic_jacobian: bool,
}

impl Robertson {
    /// The initial state at t = 0.
    pub const Y0: [f64; 3] = [1.0, 0.0, 0.0];
    /// Reference solution at t = 40 (Hairer & Wanner; IVP test-set literature).
    pub const Y_AT_40: [f64; 3] = [
        0.715_827_068_719_377,
        9.185_534_764_557_338e-6,
        0.284_163_745_745_862,
    ];
}

impl OdeProblem for Robertson {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&mut self, _t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        f[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
        f[2] = 3e7 * y[1] * y[1];
        f[1] = -f[0] - f[2];
        Ok(())
    }
    fn jacobian(
        &mut self,
        _t: f64,
        y: &[f64],
        mut j: MatMut<'_, f64>,
    ) -> Result<bool, ProblemError> {
        if !self.analytic_jacobian {
            return Ok(false);
        }
        j[(0, 0)] = -0.04;
        j[(0, 1)] = 1e4 * y[2];
        j[(0, 2)] = 1e4 * y[1];
        j[(2, 0)] = 0.0;
        j[(2, 1)] = 6e7 * y[1];
        j[(2, 2)] = 0.0;
        j[(1, 0)] = 0.04;
        j[(1, 1)] = -1e4 * y[2] - 6e7 * y[1];
        j[(1, 2)] = -1e4 * y[1];
        Ok(true)
    }
}

/// Van der Pol oscillator `y0' = y1, y1' = mu (1 - y0^2) y1 - y0`.
#[derive(Debug, Clone)]
pub struct VanDerPol {
    /// Nonlinear damping parameter (large: stiff relaxation oscillations).
    pub mu: f64,
}

impl OdeProblem for VanDerPol {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        f[0] = y[1];
        f[1] = self.mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
        Ok(())
    }
    fn jacobian(
        &mut self,
        _t: f64,
        y: &[f64],
        mut j: MatMut<'_, f64>,
    ) -> Result<bool, ProblemError> {
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -2.0 * self.mu * y[0] * y[1] - 1.0;
        j[(1, 1)] = self.mu * (1.0 - y[0] * y[0]);
        Ok(true)
    }
}

/// Linear spring–mass chain with modal damping and harmonic forcing; exact solution by modal
/// superposition.
///
/// 19 equal masses in a fixed–free chain (modes about 4–100 Hz) and one light mass on a stiff
/// spring (about 2 kHz) hung from the middle mass: 20 degrees of freedom, 40 states
/// `y = [x; v]`. Damping is 1 % in every mode, built as `C = M Phi diag(2 zeta omega) Phi^T M`.
/// A force `F0 sin(2 pi 25 t)` acts on the middle mass, where the stiff mode is attached, so the
/// 2 kHz mode is excited (the case in which BDF3–5 stall without stability-limit detection).
#[derive(Debug, Clone)]
pub struct SpringChain {
    /// Diagonal of the mass matrix (kg).
    pub mass: Vec<f64>,
    /// Stiffness matrix (N/m).
    pub stiffness: Mat<f64>,
    /// Damping matrix (N s/m), `M Phi diag(2 zeta omega) Phi^T M`.
    pub damping: Mat<f64>,
    /// Mass-normalised mode shapes (columns).
    pub modes: Mat<f64>,
    /// Undamped natural circular frequencies (rad/s), ascending.
    pub omega: Vec<f64>,
    /// Modal damping ratio of every mode.
    pub zeta: f64,
    /// Degree of freedom the harmonic force acts on.
    pub force_dof: usize,
    /// Amplitude of the harmonic force (N).
    pub force_amplitude: f64,
    /// Circular frequency of the harmonic force (rad/s).
    pub force_omega: f64,
    /// Formulate as `diag(I, M) y' = f` instead of `y' = M^{-1} f`.
    pub use_mass_matrix: bool,
}

impl SpringChain {
    /// The standard 20-DOF chain described on the type.
    pub fn standard(use_mass_matrix: bool) -> Result<Self, String> {
        let chain = 19;
        let n = chain + 1;
        let m = 1.0;
        // Top chain mode 100 Hz: omega_r = 2 sqrt(k/m) sin((2r-1) pi / (2 (2N+1))).
        let top = (((2 * chain - 1) as f64) * PI / (2.0 * (2 * chain + 1) as f64)).sin();
        let sqrt_km = 2.0 * PI * 100.0 / (2.0 * top);
        let k = m * sqrt_km * sqrt_km;
        let m_small = 0.01;
        let k_small = m_small * (2.0 * PI * 2000.0_f64).powi(2);
        let attach = chain / 2;
        let mut mass = vec![m; n];
        mass[chain] = m_small;
        let mut kk = Mat::<f64>::zeros(n, n);
        for i in 0..chain {
            // Spring to the previous mass (or to the ground for i = 0).
            kk[(i, i)] += k;
            if i > 0 {
                kk[(i - 1, i - 1)] += k;
                kk[(i - 1, i)] -= k;
                kk[(i, i - 1)] -= k;
            }
        }
        kk[(attach, attach)] += k_small;
        kk[(chain, chain)] += k_small;
        kk[(attach, chain)] -= k_small;
        kk[(chain, attach)] -= k_small;
        Self::from_matrices(
            mass,
            kk,
            0.01,
            attach,
            100.0,
            2.0 * PI * 25.0,
            use_mass_matrix,
        )
    }

    /// The 19-mass chain of [`Self::standard`] without the stiff mode (modes 4–100 Hz only),
    /// forced at its free end: a smooth, non-stiff-stalling problem.
    pub fn without_stiff_mode() -> Result<Self, String> {
        let chain = 19;
        let top = (((2 * chain - 1) as f64) * PI / (2.0 * (2 * chain + 1) as f64)).sin();
        let sqrt_km = 2.0 * PI * 100.0 / (2.0 * top);
        let k = sqrt_km * sqrt_km;
        let mut kk = Mat::<f64>::zeros(chain, chain);
        for i in 0..chain {
            kk[(i, i)] += k;
            if i > 0 {
                kk[(i - 1, i - 1)] += k;
                kk[(i - 1, i)] -= k;
                kk[(i, i - 1)] -= k;
            }
        }
        Self::from_matrices(
            vec![1.0; chain],
            kk,
            0.01,
            chain - 1,
            100.0,
            2.0 * PI * 25.0,
            false,
        )
    }

    /// Builds the chain from diagonal masses and a stiffness matrix.
    pub fn from_matrices(
        mass: Vec<f64>,
        stiffness: Mat<f64>,
        zeta: f64,
        force_dof: usize,
        force_amplitude: f64,
        force_omega: f64,
        use_mass_matrix: bool,
    ) -> Result<Self, String> {
        let n = mass.len();
        if stiffness.nrows() != n || stiffness.ncols() != n {
            return Err(format!(
                "stiffness is {}x{}, expected {n}x{n}",
                stiffness.nrows(),
                stiffness.ncols()
            ));
        }
        if let Some(i) = mass.iter().position(|m| !(m.is_finite() && *m > 0.0)) {
            return Err(format!("mass {i} must be finite and > 0, got {}", mass[i]));
        }
        if force_dof >= n {
            return Err(format!(
                "force_dof {force_dof} is not one of the {n} degrees of freedom"
            ));
        }
        // K~ = M^{-1/2} K M^{-1/2}, symmetric; its eigenvectors give the modes.
        let ktilde = Mat::from_fn(n, n, |i, j| stiffness[(i, j)] / (mass[i] * mass[j]).sqrt());
        let (omega, modes) = match ktilde.self_adjoint_eigen(Side::Lower) {
            Ok(evd) => {
                let s = evd.S();
                let u = evd.U();
                let omega: Vec<f64> = (0..n).map(|r| s[r].max(0.0).sqrt()).collect();
                let modes = Mat::from_fn(n, n, |i, r| u[(i, r)] / mass[i].sqrt());
                (omega, modes)
            }
            Err(e) => return Err(format!("modal decomposition failed: {e:?}")),
        };
        // C = M Phi diag(2 zeta omega) Phi^T M
        let damping = Mat::from_fn(n, n, |i, j| {
            (0..n)
                .map(|r| mass[i] * modes[(i, r)] * 2.0 * zeta * omega[r] * modes[(j, r)] * mass[j])
                .sum()
        });
        Ok(Self {
            mass,
            stiffness,
            damping,
            modes,
            omega,
            zeta,
            force_dof,
            force_amplitude,
            force_omega,
            use_mass_matrix,
        })
    }

    /// Number of states (twice the degrees of freedom).
    pub fn dim2(&self) -> usize {
        2 * self.mass.len()
    }

    /// Number of degrees of freedom (masses).
    pub fn dofs(&self) -> usize {
        self.mass.len()
    }

    /// Natural frequencies in Hz.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.omega.iter().map(|w| w / (2.0 * PI)).collect()
    }

    fn force(&self, t: f64, i: usize) -> f64 {
        if i == self.force_dof {
            self.force_amplitude * (self.force_omega * t).sin()
        } else {
            0.0
        }
    }

    /// Exact state `[x; v]` at `t` from the initial state `y0` (modal superposition).
    pub fn exact(&self, y0: &[f64], t: f64) -> Vec<f64> {
        let n = self.dofs();
        let w = self.force_omega;
        let mut y = vec![0.0; 2 * n];
        for r in 0..n {
            let phi = |i: usize| self.modes[(i, r)];
            let q0: f64 = (0..n).map(|i| phi(i) * self.mass[i] * y0[i]).sum();
            let qd0: f64 = (0..n).map(|i| phi(i) * self.mass[i] * y0[n + i]).sum();
            let p = phi(self.force_dof) * self.force_amplitude;
            let om = self.omega[r];
            let z = self.zeta;
            let d = (om * om - w * w).powi(2) + (2.0 * z * om * w).powi(2);
            let a = p * (om * om - w * w) / d;
            let b = -p * 2.0 * z * om * w / d;
            let wd = om * (1.0 - z * z).sqrt();
            let c1 = q0 - b;
            let c2 = (qd0 + z * om * c1 - a * w) / wd;
            let e = (-z * om * t).exp();
            let (cs, sn) = ((wd * t).cos(), (wd * t).sin());
            let q = a * (w * t).sin() + b * (w * t).cos() + e * (c1 * cs + c2 * sn);
            let qd = a * w * (w * t).cos() - b * w * (w * t).sin()
                + e * ((-z * om) * (c1 * cs + c2 * sn) + wd * (-c1 * sn + c2 * cs));
            for i in 0..n {
                y[i] += phi(i) * q;
                y[n + i] += phi(i) * qd;
            }
        }
        y
    }
}

impl OdeProblem for SpringChain {
    fn dim(&self) -> usize {
        2 * self.dofs()
    }
    fn rhs(&mut self, t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        let n = self.dofs();
        let (x, v) = y.split_at(n);
        let (fx, fv) = f.split_at_mut(n);
        fx.copy_from_slice(v);
        for (i, out) in fv.iter_mut().enumerate() {
            *out = self.force(t, i);
        }
        for j in 0..n {
            let kc = self.stiffness.col_as_slice(j);
            let cc = self.damping.col_as_slice(j);
            for i in 0..n {
                fv[i] -= kc[i] * x[j] + cc[i] * v[j];
            }
        }
        if !self.use_mass_matrix {
            for (o, m) in fv.iter_mut().zip(&self.mass) {
                *o /= m;
            }
        }
        Ok(())
    }
    fn has_mass_matrix(&self) -> bool {
        self.use_mass_matrix
    }
    fn mass_is_constant(&self) -> bool {
        true
    }
    fn mass(&mut self, _t: f64, _y: &[f64], mut m: MatMut<'_, f64>) -> Result<(), ProblemError> {
        let n = self.dofs();
        for i in 0..n {
            m[(i, i)] = 1.0;
            m[(n + i, n + i)] = self.mass[i];
        }
        Ok(())
    }
    fn jacobian(
        &mut self,
        _t: f64,
        _y: &[f64],
        mut j: MatMut<'_, f64>,
    ) -> Result<bool, ProblemError> {
        let n = self.dofs();
        for i in 0..n {
            j[(i, n + i)] = 1.0;
            let scale = if self.use_mass_matrix {
                1.0
            } else {
                1.0 / self.mass[i]
            };
            for c in 0..n {
                j[(n + i, c)] = -self.stiffness[(i, c)] * scale;
                j[(n + i, n + c)] = -self.damping[(i, c)] * scale;
            }
        }
        Ok(true)
    }
}

/// The 19-mass chain of [`SpringChain::without_stiff_mode`] in its own modal coordinates, with a
/// two-mass absorber hung from its middle mass (0.01 kg at 2 kHz, then 0.005 kg at 700 Hz, each
/// spring with a parallel dashpot of 5 % critical damping): a modal body
/// coupled to a small multibody part through one spring, the shape a block-diagonal plus
/// low-rank Jacobian is made for. State `[x1, x2, v1, v2 | η_1 … η_19 | η̇_1 … η̇_19]`.
/// With `structured` false it declares no structure and hands out the same Jacobian dense.
#[derive(Debug, Clone)]
pub struct ModalChainWithAbsorber {
    /// The 19-mass chain the absorber hangs from.
    pub chain: SpringChain,
    /// Degree of freedom of the chain the absorber is attached to.
    pub attach: usize,
    /// Absorber masses (kg): the first on the chain, the second on the first.
    pub masses: [f64; 2],
    /// Spring rates (N/m) of the chain-to-first and first-to-second springs.
    pub springs: [f64; 2],
    /// Dashpot rates (N s/m) in parallel with the springs.
    pub dashpots: [f64; 2],
    /// Whether the problem declares its block-diagonal plus low-rank Jacobian structure.
    pub structured: bool,
}

impl ModalChainWithAbsorber {
    /// The chain with the absorber at its middle mass (2 kHz and 700 Hz, 5 % damping).
    pub fn new(structured: bool) -> Result<Self, String> {
        let chain = SpringChain::without_stiff_mode()?;
        let attach = chain.dofs() / 2;
        let masses = [0.01, 0.005];
        let w1 = 2.0 * PI * 2000.0;
        let w2 = 2.0 * PI * 700.0;
        Ok(Self {
            chain,
            attach,
            masses,
            springs: [masses[0] * w1 * w1, masses[1] * w2 * w2],
            dashpots: [0.1 * masses[0] * w1, 0.1 * masses[1] * w2],
            structured,
        })
    }

    fn modes(&self) -> usize {
        self.chain.dofs()
    }

    /// Mass-normalised mode shape `r` at the attachment.
    fn phi(&self, r: usize) -> f64 {
        self.chain.modes[(self.attach, r)]
    }

    /// Block structure: the absorber's four states as one block, each mode's pair as one, rank 2.
    pub fn shape(&self) -> BlockLowRankShape {
        let m = self.modes();
        let mut blocks = vec![vec![0, 1, 2, 3]];
        blocks.extend((0..m).map(|r| vec![4 + r, 4 + m + r]));
        BlockLowRankShape { blocks, rank: 2 }
    }

    fn fill(&self, j: &mut BlockLowRankJacobian) {
        let m = self.modes();
        let ([m1, m2], [k1, k2], [c1, c2]) = (self.masses, self.springs, self.dashpots);
        let mut b = j.block_mut(0);
        b[(0, 2)] = 1.0;
        b[(1, 3)] = 1.0;
        b[(2, 0)] = -(k1 + k2) / m1;
        b[(2, 1)] = k2 / m1;
        b[(3, 0)] = k2 / m2;
        b[(3, 1)] = -k2 / m2;
        b[(2, 2)] = -(c1 + c2) / m1;
        b[(2, 3)] = c2 / m1;
        b[(3, 2)] = c2 / m2;
        b[(3, 3)] = -c2 / m2;
        for r in 0..m {
            let w = self.chain.omega[r];
            let mut b = j.block_mut(1 + r);
            b[(0, 1)] = 1.0;
            b[(1, 0)] = -w * w;
            b[(1, 1)] = -2.0 * self.chain.zeta * w;
        }
        // The absorber's first spring and dashpot carry s1 = k1 (x1 − u_a) + c1 (v1 − u̇_a) with
        // u_a = Σ φ_r η_r. Column 0: ∂s1/∂(η, η̇) acting on mass 1 and on every mode; column 1:
        // ∂s1/∂(x1, v1) acting on every mode.
        for r in 0..m {
            let phi = self.phi(r);
            j.u_mut()[(4 + m + r, 0)] = -phi;
            j.v_mut()[(4 + r, 0)] = k1 * phi;
            j.v_mut()[(4 + m + r, 0)] = c1 * phi;
            j.u_mut()[(4 + m + r, 1)] = phi;
        }
        j.u_mut()[(2, 0)] = 1.0 / m1;
        j.v_mut()[(0, 1)] = k1;
        j.v_mut()[(2, 1)] = c1;
    }
}

impl OdeProblem for ModalChainWithAbsorber {
    fn dim(&self) -> usize {
        4 + 2 * self.modes()
    }
    fn rhs(&mut self, t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        let m = self.modes();
        let ([m1, m2], [k1, k2], [c1, c2]) = (self.masses, self.springs, self.dashpots);
        let u_a: f64 = (0..m).map(|r| self.phi(r) * y[4 + r]).sum();
        let v_a: f64 = (0..m).map(|r| self.phi(r) * y[4 + m + r]).sum();
        let s1 = k1 * (y[0] - u_a) + c1 * (y[2] - v_a);
        let s2 = k2 * (y[1] - y[0]) + c2 * (y[3] - y[2]);
        f[0] = y[2];
        f[1] = y[3];
        f[2] = (-s1 + s2) / m1;
        f[3] = -s2 / m2;
        let load = self.chain.force_amplitude * (self.chain.force_omega * t).sin();
        for r in 0..m {
            let (eta, rate) = (y[4 + r], y[4 + m + r]);
            let w = self.chain.omega[r];
            f[4 + r] = rate;
            f[4 + m + r] = -w * w * eta - 2.0 * self.chain.zeta * w * rate
                + self.chain.modes[(self.chain.force_dof, r)] * load
                + self.phi(r) * s1;
        }
        Ok(())
    }
    fn jacobian(&mut self, _t: f64, _y: &[f64], j: MatMut<'_, f64>) -> Result<bool, ProblemError> {
        let mut s = BlockLowRankJacobian::new(self.shape());
        self.fill(&mut s);
        s.to_dense(j);
        Ok(true)
    }
    fn jacobian_structure(&self) -> Option<BlockLowRankShape> {
        self.structured.then(|| self.shape())
    }
    fn structured_jacobian(
        &mut self,
        _t: f64,
        _y: &[f64],
        j: &mut BlockLowRankJacobian,
    ) -> Result<(), ProblemError> {
        self.fill(j);
        Ok(())
    }
}
