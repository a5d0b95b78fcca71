//! Outputs of the hybrid scene at a communication point: the engine outputs (mount forces against
//! the moving chassis) and the steering-wheel and seat-rail accelerations, all from one evaluation
//! of the coupled equations of motion (`a_p = Σ_k φ_{p,k}[0..3] η̈_k`, no finite differences).

use nalgebra::Vector3;

use super::hybrid_scene::HybridScene;
use super::outputs::EngineOutputs;
use crate::ode::ProblemError;

/// All outputs of the hybrid scene at one time.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HybridOutputs {
    pub engine: EngineOutputs,
    /// Steering-wheel acceleration (m/s², vehicle frame).
    pub steering_wheel_acceleration: [f64; 3],
    /// Seat-rail acceleration (m/s², vehicle frame).
    pub seat_acceleration: [f64; 3],
    /// Displacement of every chassis recovery point (name, m, vehicle frame).
    pub chassis_displacements: Vec<(String, [f64; 3])>,
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

impl HybridScene {
    /// Outputs at `(t, y)`.
    pub fn outputs(&self, t: f64, y: &[f64]) -> Result<HybridOutputs, ProblemError> {
        self.check_state(y)?;
        let ne = self.engine_dim();
        let m = self.modes_count();
        let ev = self.evaluate(t, y);
        let engine = self.engine().outputs_from(t, &y[..ne], &ev.engine)?;
        let mut f = vec![0.0; y.len()];
        self.write_rhs(y, &ev, &mut f)?;
        let eta_acc = &f[self.eta_rate_index()..];
        let (wheel, seat) = self.output_points();
        let eta = &y[ne..ne + m];
        Ok(HybridOutputs {
            engine,
            steering_wheel_acceleration: arr(&self.point_translation(wheel, eta_acc)),
            seat_acceleration: arr(&self.point_translation(seat, eta_acc)),
            chassis_displacements: self
                .chassis()
                .points
                .iter()
                .enumerate()
                .map(|(p, point)| (point.name.clone(), arr(&self.point_translation(p, eta))))
                .collect(),
        })
    }
}
