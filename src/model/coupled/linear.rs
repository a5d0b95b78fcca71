//! The coupled model linearised at its static equilibrium as a state-space system
//! `x' = A x + B u`, `y = C x + D u`: the transfer functions of the coupled system (engine on its
//! mounts in the body) and the state matrix of the modal analysis ([`super::modes`]).
//!
//! States `x` are the vibration coordinates ([`super::StateLayout::vibration_coordinates`]:
//! powertrain positions and velocities, modal coordinates and rates). The input `u` is the load
//! torque (N m about the crank axis on the housing: the drivetrain's reaction, and the
//! direction of the inline-3's gas and mass torques). The outputs are the accelerations of every
//! body point (m/s², vehicle axes), the force of every mount on the body (N) and the
//! acceleration of the housing's centre of mass (m/s²). Everything is evaluated with the engine
//! at rest (crank standing, no gas, mounts linearised at their operating points), as for the
//! natural modes, by central differences of the model's own equations.

use faer::Mat;
use nalgebra::Vector3;

use super::evaluate::Mode;
use super::CoupledModel;

/// Step of the central differences over the vibration coordinates (m, rad, m/s, rad/s and modal
/// units): the same as the modal analysis used before it was shared here.
const STATE_STEP: f64 = 1e-7;

/// Step of the central difference over the load torque (N m). The equations are affine in the
/// load torque, so the step only has to stand clear of round-off.
const TORQUE_STEP: f64 = 1.0;

/// The linearised coupled system.
#[derive(Debug, Clone)]
pub struct Linearisation {
    /// Names of the states, in order (`"powertrain.q[3]"`, `"eta[12]"`, …).
    pub states: Vec<String>,
    /// Names of the inputs: `["loadTorque"]`.
    pub inputs: Vec<String>,
    /// Names of the outputs: `"<point>.a[j]"` for every body point, `"mount[i].F[j]"` for every
    /// configured mount (1-based, as the FMU names them), `"powertrain.a[j]"`.
    pub outputs: Vec<String>,
    /// `∂x'/∂x`.
    pub a: Mat<f64>,
    /// `∂x'/∂u`.
    pub b: Mat<f64>,
    /// `∂y/∂x`.
    pub c: Mat<f64>,
    /// `∂y/∂u`.
    pub d: Mat<f64>,
}

impl CoupledModel {
    /// `∂f/∂x` over the vibration coordinates at `y_eq`, engine at rest.
    pub(super) fn state_matrix(&self, y_eq: &[f64]) -> Result<Mat<f64>, String> {
        self.check_state(y_eq).map_err(|e| format!("{e:?}"))?;
        let coords = self.layout.vibration_coordinates();
        let n = coords.len();
        let dim = self.layout.dim();
        let mut jac = Mat::<f64>::zeros(n, n);
        let mut fp = vec![0.0; dim];
        let mut fm = vec![0.0; dim];
        let mut y = y_eq.to_vec();
        for (c, &jc) in coords.iter().enumerate() {
            y[jc] = y_eq[jc] + STATE_STEP;
            self.rhs_at_rest(&y, &mut fp)
                .map_err(|e| format!("linearisation failed: {e:?}"))?;
            y[jc] = y_eq[jc] - STATE_STEP;
            self.rhs_at_rest(&y, &mut fm)
                .map_err(|e| format!("linearisation failed: {e:?}"))?;
            y[jc] = y_eq[jc];
            for (r, &ir) in coords.iter().enumerate() {
                jac[(r, c)] = (fp[ir] - fm[ir]) / (2.0 * STATE_STEP);
            }
        }
        Ok(jac)
    }

    /// The outputs of [`Linearisation`] at `y` with the engine at rest.
    fn outputs_at_rest(&self, y: &[f64]) -> Result<Vec<f64>, String> {
        let t = self.fade_start;
        let ev = self.evaluate_mode(t, y, Mode::AT_REST);
        let mut f = vec![0.0; y.len()];
        self.write_rhs(t, y, &ev, Mode::AT_REST, &mut f)
            .map_err(|e| format!("linearisation failed: {e:?}"))?;
        let mut out = Vec::new();
        let eta_acc = &f[self.layout.eta_rate()];
        for p in 0..self.body.points.len() {
            out.extend_from_slice(self.point_translation(p, eta_acc).as_slice());
        }
        for m in &ev.mounts {
            let force = m.map_or(Vector3::zeros(), |r| -r.force);
            out.extend_from_slice(force.as_slice());
        }
        let hb = self.powertrain.housing_index();
        let k = &ev.kinematics[hb];
        let acc = &f[self.layout.v(hb)];
        let r = k.rotation
            * (self.powertrain.housing_reference() - self.powertrain.bodies()[hb].reference);
        let alpha = Vector3::new(acc[3], acc[4], acc[5]);
        let a = Vector3::new(acc[0], acc[1], acc[2])
            + alpha.cross(&r)
            + k.omega.cross(&k.omega.cross(&r));
        out.extend_from_slice(a.as_slice());
        Ok(out)
    }

    fn linear_output_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        for p in &self.body.points {
            names.extend((1..=3).map(|j| format!("{}.a[{j}]", p.name)));
        }
        for i in 1..=self.mounts.len() {
            names.extend((1..=3).map(|j| format!("mount[{i}].F[{j}]")));
        }
        names.extend((1..=3).map(|j| format!("powertrain.a[{j}]")));
        names
    }

    fn state_names(&self) -> Vec<String> {
        let nb = self.layout.bodies();
        let body = |b: usize| self.powertrain.bodies()[b].name.clone();
        let mut names = Vec::new();
        for b in 0..nb {
            names.extend((1..=6).map(|j| format!("{}.q[{j}]", body(b))));
        }
        for b in 0..nb {
            names.extend((1..=6).map(|j| format!("{}.v[{j}]", body(b))));
        }
        let m = self.layout.modes();
        names.extend((1..=m).map(|k| format!("eta[{k}]")));
        names.extend((1..=m).map(|k| format!("eta_rate[{k}]")));
        names
    }

    /// The system linearised at the static equilibrium `y_eq` under the load torque in force.
    pub fn linearise(&self, y_eq: &[f64]) -> Result<Linearisation, String> {
        let a = self.state_matrix(y_eq)?;
        let coords = self.layout.vibration_coordinates();
        let (n, dim) = (coords.len(), self.layout.dim());
        let y0 = self.outputs_at_rest(y_eq)?;
        let p = y0.len();
        let mut c = Mat::<f64>::zeros(p, n);
        let mut y = y_eq.to_vec();
        for (col, &jc) in coords.iter().enumerate() {
            y[jc] = y_eq[jc] + STATE_STEP;
            let plus = self.outputs_at_rest(&y)?;
            y[jc] = y_eq[jc] - STATE_STEP;
            let minus = self.outputs_at_rest(&y)?;
            y[jc] = y_eq[jc];
            for r in 0..p {
                c[(r, col)] = (plus[r] - minus[r]) / (2.0 * STATE_STEP);
            }
        }
        // The load torque: the same model under a torque a step higher and lower.
        let torque = self.inputs.load_torque.at(self.fade_start);
        let with_torque = |value: f64| -> Result<(Vec<f64>, Vec<f64>), String> {
            let mut model = self.clone();
            model
                .set_load_torque(self.fade_start, value, 0.0)
                .map_err(|e| format!("linearisation: {}", e))?;
            let mut f = vec![0.0; dim];
            model
                .rhs_at_rest(y_eq, &mut f)
                .map_err(|e| format!("linearisation failed: {e:?}"))?;
            Ok((f, model.outputs_at_rest(y_eq)?))
        };
        let (fp, yp) = with_torque(torque + TORQUE_STEP)?;
        let (fm, ym) = with_torque(torque - TORQUE_STEP)?;
        let b = Mat::from_fn(n, 1, |r, _| {
            (fp[coords[r]] - fm[coords[r]]) / (2.0 * TORQUE_STEP)
        });
        let d = Mat::from_fn(p, 1, |r, _| (yp[r] - ym[r]) / (2.0 * TORQUE_STEP));
        Ok(Linearisation {
            states: self.state_names(),
            inputs: vec!["loadTorque".into()],
            outputs: self.linear_output_names(),
            a,
            b,
            c,
            d,
        })
    }
}
