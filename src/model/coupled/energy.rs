//! Total mechanical energy of the coupled model, for conservation checks.

use nalgebra::Vector6;

use super::CoupledModel;
use crate::ode::ProblemError;

impl CoupledModel {
    /// Kinetic energy of the powertrain, its potential in gravity, the elastic energy of mounts
    /// and ring carriers (preload work included) and the modal energy of the body.
    pub fn energy(&self, t: f64, y: &[f64]) -> Result<f64, ProblemError> {
        self.check_state(y)?;
        let ev = self.evaluate(t, y);
        let l = &self.layout;
        let mut e = 0.0;
        for b in 0..l.bodies() {
            let v = Vector6::from_column_slice(&y[l.v(b)]);
            e += 0.5 * v.dot(&(ev.dynamics[b].mass * v));
            for part in &self.powertrain.bodies()[b].parts {
                let x = ev.kinematics[b].point(&part.path(ev.crank.angle).rho);
                e -= part.mass * self.powertrain.gravity().dot(&x);
            }
        }
        let nonlinear = self.effects().mount_nonlinearity;
        for (i, m) in self.mounts.iter().enumerate() {
            if let (Some(m), Some(r)) = (m, &ev.mounts[i]) {
                let k_scale = self.inputs.mount_scales(i, t).0;
                e += m.mount.energy(&r.deflection, k_scale, nonlinear);
            }
        }
        if l.bodies() == 2 {
            for rc in self.powertrain.ring_carriers() {
                e += rc.energy(&rc.wrench(&ev.kinematics[0], &ev.kinematics[1]).deflection);
            }
        }
        let (eta, rate) = (&y[l.eta()], &y[l.eta_rate()]);
        for k in 0..l.modes() {
            let w = self.body.omega[k];
            e += 0.5 * (rate[k] * rate[k] + w * w * eta[k] * eta[k]);
        }
        Ok(e)
    }
}
