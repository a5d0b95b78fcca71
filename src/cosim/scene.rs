//! The scenes the FMU can simulate, behind one type the runtime steps.

use faer::MatMut;

use super::{Inputs, Outputs, Settings};
use crate::model::{EngineConfig, GroundScene};
use crate::ode::{OdeProblem, ProblemError};

/// Number of mounts the FMU's variables expose (`mount[1..4]`).
pub const FMU_MOUNTS: usize = 4;

/// A model the runtime can integrate. An enum rather than a trait object: scenes are cloned for
/// FMU states and the set is closed.
#[derive(Clone)]
pub enum Scene {
    /// Engine on rigid ground (paper Table 1, left column).
    Ground(GroundScene),
}

/// Reads the engine configuration the settings name, with the FMU parameters applied on top.
fn engine_config(settings: &Settings) -> Result<EngineConfig, String> {
    let mut config = match &settings.config_file {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| format!("cannot read configuration {}: {e}", path.display()))?;
            EngineConfig::from_json(&text)
                .map_err(|e| format!("configuration {}: {e}", path.display()))?
        }
        None => EngineConfig::default(),
    };
    let e = &settings.effects;
    config.effects.gas_forces = e.gas_forces;
    config.effects.mass_forces = e.mass_forces;
    config.effects.balance_shaft = e.balance_shaft;
    config.effects.gyroscopic = e.gyroscopic;
    config.effects.ring_carrier_elasticity = e.ring_carrier;
    config.effects.mount_nonlinearity = e.mount_nonlinearity;
    config.excitation_fade_in = settings.fade_in_time;
    config.start_crank_angle_deg = settings.crank_start_angle.to_degrees();
    if config.mounts.len() > FMU_MOUNTS {
        return Err(format!(
            "the configuration has {} mounts; the FMU exposes {FMU_MOUNTS} (deactivate one with \"active\": false)",
            config.mounts.len()
        ));
    }
    Ok(config)
}

impl Scene {
    pub fn build(settings: &Settings) -> Result<Scene, String> {
        match settings.scene {
            1 => {
                let config = engine_config(settings)?;
                GroundScene::new(config)
                    .map(Scene::Ground)
                    .map_err(|e| e.to_string())
            }
            other => Err(format!(
                "scene {other} is not available (1 = engine on rigid ground)"
            )),
        }
    }

    pub fn set_inputs(&mut self, inputs: &Inputs) -> Result<(), String> {
        match self {
            Scene::Ground(g) => {
                let w = &inputs.crank_speed;
                g.set_crank_speed(w.reference_time, w.value, w.derivative)
                    .map_err(|e| e.0)?;
                let m = &inputs.load_torque;
                g.set_load_torque(m.reference_time, m.value, m.derivative)
                    .map_err(|e| e.0)?;
                for i in 0..g.config().mounts.len().min(FMU_MOUNTS) {
                    g.set_mount_scales(
                        i,
                        inputs.stiffness_scale[i].value,
                        inputs.damping_scale[i].value,
                    )
                    .map_err(|e| e.0)?;
                }
                Ok(())
            }
        }
    }

    /// Per state, the largest magnitude the integrator's relative tolerance applies to: one
    /// revolution for the cumulative crank angle (its phase is what must stay accurate), no cap
    /// elsewhere.
    pub fn magnitude_caps(&self) -> Vec<f64> {
        let mut caps = vec![f64::INFINITY; self.dim()];
        match self {
            Scene::Ground(g) => caps[g.crank_index()] = 2.0 * std::f64::consts::PI,
        }
        caps
    }

    /// The static equilibrium under the current inputs; the excitation fades in from `t0`.
    pub fn initial_state(&mut self, t0: f64) -> Result<Vec<f64>, String> {
        match self {
            Scene::Ground(g) => g.static_equilibrium(t0).map_err(|e| e.to_string()),
        }
    }

    pub fn outputs(&self, t: f64, y: &[f64]) -> Result<Outputs, String> {
        match self {
            Scene::Ground(g) => {
                let o = g.outputs(t, y).map_err(|e| format!("{e:?}"))?;
                let mut out = Outputs {
                    crank_angle: o.crank_angle,
                    powertrain_displacement: o.housing.displacement,
                    powertrain_rotation: o.housing.rotation,
                    powertrain_acceleration: o.housing.acceleration,
                    ..Outputs::default()
                };
                for (slot, f) in out.mount_force.iter_mut().zip(&o.mount_forces) {
                    *slot = *f;
                }
                Ok(out)
            }
        }
    }

    pub fn describe(&self) -> Vec<String> {
        match self {
            Scene::Ground(g) => {
                let c = g.config();
                let active = c.mounts.iter().filter(|m| m.active).count();
                vec![format!(
                    "scene 1 (engine on rigid ground): {} bodies, {active} of {} mounts active, {} states; effects {:?}",
                    g.body_count(),
                    c.mounts.len(),
                    g.dim(),
                    c.effects
                )]
            }
        }
    }
}

impl OdeProblem for Scene {
    fn dim(&self) -> usize {
        match self {
            Scene::Ground(g) => g.dim(),
        }
    }

    fn rhs(&mut self, t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        match self {
            Scene::Ground(g) => g.rhs(t, y, f),
        }
    }

    fn has_mass_matrix(&self) -> bool {
        match self {
            Scene::Ground(g) => g.has_mass_matrix(),
        }
    }

    fn mass(&mut self, t: f64, y: &[f64], m: MatMut<'_, f64>) -> Result<(), ProblemError> {
        match self {
            Scene::Ground(g) => g.mass(t, y, m),
        }
    }

    fn jacobian(&mut self, t: f64, y: &[f64], j: MatMut<'_, f64>) -> Result<bool, ProblemError> {
        match self {
            Scene::Ground(g) => g.jacobian(t, y, j),
        }
    }
}
