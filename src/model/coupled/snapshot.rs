//! The mutable data of a [`CoupledModel`] besides the integrator state: inputs, fade-in start,
//! mount operating points and gas load. An FMU state captures it with the integrator history.

use serde::{Deserialize, Serialize};

use super::CoupledModel;
use crate::model::inputs::{InputError, ModelInputs};

/// Everything about a model that changes after construction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSnapshot {
    /// The inputs in force.
    pub inputs: ModelInputs,
    /// Start time of the excitation fade-in (s).
    pub fade_start: f64,
    /// Per configured mount (zeros for removed mounts).
    pub operating_points: Vec<[f64; 3]>,
    /// Combustion load between idle (0) and full load (1).
    pub gas_load: f64,
}

impl CoupledModel {
    /// The model's mutable data.
    pub fn snapshot(&self) -> ModelSnapshot {
        ModelSnapshot {
            inputs: self.inputs.clone(),
            fade_start: self.fade_start,
            operating_points: self.operating_points(),
            gas_load: self.powertrain.config().gas.load,
        }
    }

    /// Restores data taken by [`Self::snapshot`] from a model with the same configuration.
    /// Validates everything first; on error the model is unchanged.
    pub fn restore(&mut self, s: &ModelSnapshot) -> Result<(), InputError> {
        let n = self.mounts.len();
        if s.operating_points.len() != n {
            return Err(InputError::Other(format!(
                "snapshot is for {} mounts, the model has {n}",
                s.operating_points.len()
            )));
        }
        if let Some((i, p)) = s
            .operating_points
            .iter()
            .enumerate()
            .find(|(_, p)| p.iter().any(|x| !x.is_finite()))
        {
            return Err(InputError::Other(format!(
                "mount {} operating point {p:?} must be finite",
                i + 1
            )));
        }
        let mut trial = self.clone();
        trial.set_inputs(&s.inputs)?;
        trial.set_fade_start(s.fade_start)?;
        if trial.effects().gas_forces && s.gas_load != trial.powertrain.config().gas.load {
            trial.set_gas_load(s.gas_load)?;
        }
        trial.set_operating_points(&s.operating_points);
        *self = trial;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::inputs::RampInput;
    use crate::model::VehicleConfig;

    #[test]
    fn snapshot_round_trips_through_serde_and_restores_the_model() {
        let cfg = VehicleConfig::default();
        let mut model = CoupledModel::on_ground(&cfg).expect("model");
        model.set_load_torque(0.0, 120.0, 0.0).expect("torque");
        model.static_equilibrium(0.3).expect("statics");
        model.set_crank_speed(0.4, 200.0, 15.0).expect("speed");
        model.set_mount_scales(1, 1.3, 0.4).expect("scales");
        model.set_gas_load(0.7).expect("load");
        let snap = model.snapshot();
        let text = serde_json::to_string(&snap).expect("serialise");
        let back: ModelSnapshot = serde_json::from_str(&text).expect("parse");
        assert_eq!(back, snap);
        let mut fresh = CoupledModel::on_ground(&cfg).expect("model");
        fresh.restore(&back).expect("restore");
        assert_eq!(fresh.snapshot(), snap);
        let mut wrong = snap.clone();
        wrong.inputs.stiffness_scale[0] = RampInput::constant(-1.0);
        let before = fresh.snapshot();
        assert!(fresh.restore(&wrong).is_err());
        assert_eq!(fresh.snapshot(), before);
        let mut bad = snap.clone();
        bad.operating_points[2][1] = f64::NAN;
        assert!(fresh.restore(&bad).is_err());
        assert_eq!(fresh.snapshot(), before);
    }
}
