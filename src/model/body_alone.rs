//! The reduced body on its suspension alone, driven by forces at its mount points: the model of
//! the body FMU, which a vehicle co-simulation couples to an engine elsewhere (an engine FMU in
//! scene 3, or the user's own).
//!
//! The body is the same [`ReducedChassis`] scene 2 couples to the powertrain: modal coordinates
//! `η̈_k + 2ζ_k ω_k η̇_k + ω_k² η_k = g_k(t)`, `g_k = Σ_i φ_{p_i,k} · F_i(t)` with `F_i` the force
//! on the body at mount point `p_i`. The equations are linear and uncoupled, and the FMI inputs
//! are ramps over a communication step, so each mode is propagated exactly: the particular
//! solution of a ramp force is itself a ramp, and the rest decays by the mode's 2 × 2 transition
//! matrix `exp(A h)`. No integrator error, no tolerance, and a step costs `O(modes)` — the
//! engine's BDF integrator would only add its error to a system it has no need to approximate.

use nalgebra::{Matrix2, Vector2, Vector3};

use super::coupled::{output_points, point_index, ModelError, OutputPoint, MOUNT_MATCH_TOLERANCE};
use super::inputs::{validate_body_forces, Input, InputError, RampInput};
use super::mount::MountConfig;
use crate::cms::ReducedChassis;

/// Motion of one body point (vehicle frame).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PointKinematics {
    /// Displacement from the reference position (m).
    pub displacement: [f64; 3],
    /// Velocity (m/s).
    pub velocity: [f64; 3],
    /// Acceleration (m/s²).
    pub acceleration: [f64; 3],
}

/// The body's outputs at one time.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BodyOutputs {
    /// Per configured mount: its body point's motion (zero for a removed mount).
    pub mounts: Vec<PointKinematics>,
    /// The output points (`steering_wheel`, `seat_rail`, …) by name.
    pub points: Vec<(String, PointKinematics)>,
}

impl BodyOutputs {
    /// The output point called `name`, if the body reports it.
    pub fn point(&self, name: &str) -> Option<&PointKinematics> {
        self.points.iter().find(|(n, _)| n == name).map(|(_, p)| p)
    }
}

/// The reduced body driven by mount forces.
#[derive(Debug, Clone)]
pub struct BodyAlone {
    body: ReducedChassis,
    /// Per configured mount: the body point it acts on (`None` for a removed mount).
    mount_points: Vec<Option<usize>>,
    outputs: Vec<OutputPoint>,
    /// Per configured mount: the force on the body, N, per vehicle axis.
    forces: Vec<[RampInput; 3]>,
    /// The largest force accepted at a mount, N ([`validate_body_forces`]).
    force_limit: f64,
}

impl BodyAlone {
    /// The body with a force input at the body node of every active mount of `mounts` and the
    /// named `outputs`, accepting forces up to `force_limit` (N) at a mount. Every mode must
    /// have a positive frequency: a body that is free in some direction has no static
    /// equilibrium under the engine's weight.
    pub fn new(
        body: ReducedChassis,
        mounts: &[MountConfig],
        outputs: &[String],
        force_limit: f64,
    ) -> Result<Self, ModelError> {
        if body.zeta.len() != body.n_modes() {
            return Err(ModelError::Body(format!(
                "{} frequencies but {} damping ratios",
                body.n_modes(),
                body.zeta.len()
            )));
        }
        for (k, (&w, &z)) in body.omega.iter().zip(&body.zeta).enumerate() {
            if !(w.is_finite() && w > 0.0 && z.is_finite() && z >= 0.0) {
                return Err(ModelError::Body(format!(
                    "body mode {k}: ω = {w} rad/s, ζ = {z}; the body alone needs every mode on \
                     its suspension (ω > 0) and finite damping ζ >= 0"
                )));
            }
        }
        let mut mount_points = Vec::with_capacity(mounts.len());
        for (i, m) in mounts.iter().enumerate() {
            if !m.active {
                mount_points.push(None);
                continue;
            }
            let node = m.body_node.as_deref().ok_or_else(|| {
                ModelError::Body(format!("mount {} ('{}') names no body node", i + 1, m.name))
            })?;
            let p = point_index(&body, node, &format!("mount '{}'", m.name))?;
            let at = Vector3::from(body.points[p].position);
            let gap = (at - Vector3::from(m.bracket)).norm();
            if gap > MOUNT_MATCH_TOLERANCE {
                return Err(ModelError::Body(format!(
                    "mount {} ('{}'): its body node '{node}' is {:.1} mm from its bracket \
                     (limit {:.1} mm)",
                    i + 1,
                    m.name,
                    gap * 1e3,
                    MOUNT_MATCH_TOLERANCE * 1e3
                )));
            }
            mount_points.push(Some(p));
        }
        let outputs = output_points(&body, outputs)?;
        Ok(Self {
            forces: vec![[RampInput::ZERO; 3]; mounts.len()],
            force_limit,
            body,
            mount_points,
            outputs,
        })
    }

    /// The reduced body.
    pub fn body(&self) -> &ReducedChassis {
        &self.body
    }

    /// Number of modal coordinates.
    pub fn modes(&self) -> usize {
        self.body.n_modes()
    }

    /// Per configured mount: the body point its force acts on (`None`: removed).
    pub fn mount_points(&self) -> &[Option<usize>] {
        &self.mount_points
    }

    /// Whether `forces` (one per configured mount) are admissible ([`validate_body_forces`]).
    pub fn check_forces(&self, forces: &[[RampInput; 3]]) -> Result<(), InputError> {
        self.check_force_count(forces)?;
        validate_body_forces(forces, self.force_limit)
    }

    /// Whether there is one force per configured mount.
    fn check_force_count(&self, forces: &[[RampInput; 3]]) -> Result<(), InputError> {
        if forces.len() != self.forces.len() {
            return Err(InputError::Other(format!(
                "{} mount forces for {} mounts",
                forces.len(),
                self.forces.len()
            )));
        }
        Ok(())
    }

    /// Sets the force on the body at each mount (configuration order), as ramps; validated as a
    /// whole ([`Self::check_forces`]), on error nothing changes.
    pub fn set_forces(&mut self, forces: &[[RampInput; 3]]) -> Result<(), InputError> {
        self.check_forces(forces)?;
        self.forces.copy_from_slice(forces);
        Ok(())
    }

    /// The body's rule for one input ([`Input::check`] with its force bound); an input the body
    /// does not have (the engine's, a mount beyond the configuration) is none of its business.
    pub fn check_input(&self, input: Input, ramp: &RampInput) -> Result<(), InputError> {
        match input {
            Input::BodyForce(i, _) if i < self.forces.len() => input.check(ramp, self.force_limit),
            _ => Ok(()),
        }
    }

    /// The forces at each mount, each of which passed its rule where it was set
    /// ([`Self::check_input`]): only their number is checked, the rules do not run again.
    pub fn set_checked_forces(&mut self, forces: &[[RampInput; 3]]) -> Result<(), InputError> {
        self.check_force_count(forces)?;
        self.forces.copy_from_slice(forces);
        Ok(())
    }

    /// Generalised force `g_k(t) = Σ_i φ_{p_i,k} · F_i(t)` per mode.
    fn modal_force(&self, t: f64) -> Vec<f64> {
        let mut g = vec![0.0; self.modes()];
        for (f, p) in self.forces.iter().zip(&self.mount_points) {
            let Some(p) = p else { continue };
            let force = f.map(|r| r.at(t));
            for (gk, s) in g.iter_mut().zip(&self.body.points[*p].shape) {
                *gk += s[0] * force[0] + s[1] * force[1] + s[2] * force[2];
            }
        }
        g
    }

    /// Static deflection under the forces at `t`: `η_k = g_k / ω_k²`, at rest. State layout:
    /// the `m` modal coordinates, then their rates.
    pub fn static_equilibrium(&self, t: f64) -> Vec<f64> {
        let m = self.modes();
        let mut y = vec![0.0; 2 * m];
        for (k, g) in self.modal_force(t).into_iter().enumerate() {
            y[k] = g / (self.body.omega[k] * self.body.omega[k]);
        }
        y
    }

    /// Propagates `y` (at `t0`) exactly to `t1` under the current force ramps.
    pub fn advance(&self, t0: f64, t1: f64, y: &mut [f64]) {
        let h = t1 - t0;
        if h == 0.0 {
            return;
        }
        let m = self.modes();
        let (g0, g1) = (self.modal_force(t0), self.modal_force(t1));
        for k in 0..m {
            let (w, z) = (self.body.omega[k], self.body.zeta[k]);
            let w2 = w * w;
            // Ramp force g(s) = a + b s: particular solution η_p = c + d s, d = b/ω²,
            // c = (a − 2ζω d)/ω², with rate d.
            let b = (g1[k] - g0[k]) / h;
            let d = b / w2;
            let particular = |g: f64| (g - 2.0 * z * w * d) / w2;
            let a_matrix = Matrix2::new(0.0, 1.0, -w2, -2.0 * z * w);
            let transition = (a_matrix * h).exp();
            let e0 = Vector2::new(y[k] - particular(g0[k]), y[m + k] - d);
            let e1 = transition * e0;
            y[k] = particular(g1[k]) + e1.x;
            y[m + k] = d + e1.y;
        }
    }

    /// Modal accelerations `η̈ = g − 2ζωη̇ − ω²η` at `(t, y)`.
    fn modal_accelerations(&self, t: f64, y: &[f64]) -> Vec<f64> {
        let m = self.modes();
        let g = self.modal_force(t);
        (0..m)
            .map(|k| {
                let (w, z) = (self.body.omega[k], self.body.zeta[k]);
                g[k] - 2.0 * z * w * y[m + k] - w * w * y[k]
            })
            .collect()
    }

    fn point_motion(&self, p: usize, y: &[f64], acc: &[f64]) -> PointKinematics {
        let m = self.modes();
        let mut out = PointKinematics::default();
        for (k, s) in self.body.points[p].shape.iter().enumerate() {
            for (j, sj) in s.iter().take(3).enumerate() {
                out.displacement[j] += sj * y[k];
                out.velocity[j] += sj * y[m + k];
                out.acceleration[j] += sj * acc[k];
            }
        }
        out
    }

    /// Motion of the mount points and output points at `(t, y)`.
    pub fn outputs(&self, t: f64, y: &[f64]) -> BodyOutputs {
        let acc = self.modal_accelerations(t, y);
        BodyOutputs {
            mounts: self
                .mount_points
                .iter()
                .map(|p| p.map_or_else(PointKinematics::default, |p| self.point_motion(p, y, &acc)))
                .collect(),
            points: self
                .outputs
                .iter()
                .map(|o| (o.name.clone(), self.point_motion(o.point, y, &acc)))
                .collect(),
        }
    }

    /// `∂a_p/∂F_q`: the acceleration of body point `p` per unit force at body point `q`
    /// (vehicle frame, 3 × 3): `Σ_k φ_{p,k} φ_{q,k}ᵀ`, the inverse of the interface mass a
    /// coupling algorithm needs. Exact: the accelerations are linear in the forces.
    pub fn acceleration_per_force(&self, p: usize, q: usize) -> [[f64; 3]; 3] {
        let mut out = [[0.0; 3]; 3];
        for (sp, sq) in self.body.points[p]
            .shape
            .iter()
            .zip(&self.body.points[q].shape)
        {
            for (r, row) in out.iter_mut().enumerate() {
                for (c, x) in row.iter_mut().enumerate() {
                    *x += sp[r] * sq[c];
                }
            }
        }
        out
    }

    /// The output points, in the order of [`BodyOutputs::points`].
    pub fn output_points(&self) -> &[OutputPoint] {
        &self.outputs
    }

    /// The body point of output `name`, if reported.
    pub fn output_point(&self, name: &str) -> Option<usize> {
        self.outputs
            .iter()
            .find(|o| o.name == name)
            .map(|o| o.point)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cms::RecoveryPoint;

    /// One mode (ω, ζ) seen at one point along z with unit shape.
    fn oscillator(omega: f64, zeta: f64) -> BodyAlone {
        let body = ReducedChassis {
            omega: vec![omega],
            zeta: vec![zeta],
            points: vec![RecoveryPoint {
                name: "p".into(),
                node: 1,
                position: [0.0; 3],
                shape: vec![[0.0, 0.0, 1.0, 0.0, 0.0, 0.0]],
            }],
            cutoff_hz: None,
            own_damping: None,
        };
        BodyAlone {
            body,
            mount_points: vec![Some(0)],
            outputs: Vec::new(),
            forces: vec![[RampInput::ZERO; 3]],
            force_limit: 1e9,
        }
    }

    #[test]
    fn a_step_force_gives_the_closed_form_damped_response() {
        // Unit mass, F = 1 from t = 0 on, at rest: x(t) = (1 − e^{−ζωt}(cos ω_d t +
        // ζ/√(1−ζ²) sin ω_d t))/ω².
        let (w, z) = (2.0 * std::f64::consts::PI * 7.0, 0.05);
        let mut b = oscillator(w, z);
        b.set_forces(&[[RampInput::ZERO, RampInput::ZERO, RampInput::constant(1.0)]])
            .unwrap();
        let mut y = vec![0.0, 0.0];
        let wd = w * (1.0 - z * z).sqrt();
        let mut t = 0.0;
        for _ in 0..37 {
            b.advance(t, t + 3.3e-3, &mut y);
            t += 3.3e-3;
            let exact = (1.0
                - (-z * w * t).exp()
                    * ((wd * t).cos() + z / (1.0 - z * z).sqrt() * (wd * t).sin()))
                / (w * w);
            assert!((y[0] - exact).abs() < 1e-12 * (1.0 / (w * w)), "t = {t}");
        }
    }

    #[test]
    fn a_ramp_force_is_followed_exactly_and_accelerations_balance() {
        // F = r t on an undamped oscillator at rest: x = r (t − sin(ωt)/ω)/ω².
        let (w, r) = (30.0, 5.0);
        let mut b = oscillator(w, 0.0);
        let ramp = RampInput {
            value: 0.0,
            rate: r,
            since: 0.0,
        };
        b.set_forces(&[[RampInput::ZERO, RampInput::ZERO, ramp]])
            .unwrap();
        let mut y = vec![0.0, 0.0];
        b.advance(0.0, 0.4, &mut y);
        let t: f64 = 0.4;
        let exact = r * (t - (w * t).sin() / w) / (w * w);
        assert!((y[0] - exact).abs() < 1e-13, "{} vs {exact}", y[0]);
        let out = b.outputs(t, &y);
        let a_exact = r * (w * t).sin() / w;
        assert!((out.mounts[0].acceleration[2] - a_exact).abs() < 1e-11);
        assert_eq!(b.acceleration_per_force(0, 0)[2][2], 1.0);
    }
}
