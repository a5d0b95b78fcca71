//! The mutable data of a [`GroundScene`] besides the integrator state: inputs, fade-in start,
//! mount operating points and gas load. An FMU snapshots it with the integrator history
//! (`fmi2GetFMUstate`) and serialises it as plain numbers (`fmi2SerializeFMUstate`).

use nalgebra::Vector3;

use super::ground_scene::GroundScene;
use super::inputs::{EngineInputs, InputError, RampInput};

/// Everything about a scene that changes after construction.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneSnapshot {
    pub inputs: EngineInputs,
    pub fade_start: f64,
    /// Per configured mount (zeros for removed mounts).
    pub operating_points: Vec<[f64; 3]>,
    pub gas_load: f64,
}

impl SceneSnapshot {
    /// Number of values [`Self::to_vec`] produces for a scene with `mounts` configured mounts.
    pub fn len_for(mounts: usize) -> usize {
        6 + 1 + 1 + 5 * mounts
    }

    /// Flat representation: crank speed (value, rate, since), load torque (value, rate, since),
    /// fade start, gas load, then per mount stiffness scale, damping scale, operating point (3).
    pub fn to_vec(&self) -> Vec<f64> {
        let c = &self.inputs.crank_speed;
        let l = &self.inputs.load_torque;
        let mut v = vec![
            c.value,
            c.rate,
            c.since,
            l.value,
            l.rate,
            l.since,
            self.fade_start,
            self.gas_load,
        ];
        for (i, p) in self.operating_points.iter().enumerate() {
            v.push(self.inputs.stiffness_scale.get(i).copied().unwrap_or(1.0));
            v.push(self.inputs.damping_scale.get(i).copied().unwrap_or(1.0));
            v.extend_from_slice(p);
        }
        v
    }

    /// Inverse of [`Self::to_vec`]; rejects a wrong length or non-finite values.
    pub fn from_slice(v: &[f64], mounts: usize) -> Result<Self, InputError> {
        let n = Self::len_for(mounts);
        if v.len() != n {
            return Err(InputError(format!(
                "scene snapshot has {} values, expected {n} for {mounts} mounts",
                v.len()
            )));
        }
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(InputError(format!("scene snapshot value {i} is {}", v[i])));
        }
        let mut inputs = EngineInputs::new(mounts);
        inputs.crank_speed = RampInput {
            value: v[0],
            rate: v[1],
            since: v[2],
        };
        inputs.load_torque = RampInput {
            value: v[3],
            rate: v[4],
            since: v[5],
        };
        let mut operating_points = Vec::with_capacity(mounts);
        for i in 0..mounts {
            let o = 8 + 5 * i;
            inputs.stiffness_scale[i] = v[o];
            inputs.damping_scale[i] = v[o + 1];
            operating_points.push([v[o + 2], v[o + 3], v[o + 4]]);
        }
        Ok(Self {
            inputs,
            fade_start: v[6],
            operating_points,
            gas_load: v[7],
        })
    }
}

impl GroundScene {
    /// The scene's mutable data.
    pub fn snapshot(&self) -> SceneSnapshot {
        SceneSnapshot {
            inputs: self.inputs().clone(),
            fade_start: self.fade_start(),
            operating_points: self
                .mounts()
                .iter()
                .map(|m| {
                    m.as_ref()
                        .map(|m| {
                            [
                                m.operating_point.x,
                                m.operating_point.y,
                                m.operating_point.z,
                            ]
                        })
                        .unwrap_or([0.0; 3])
                })
                .collect(),
            gas_load: self.config().gas.load,
        }
    }

    /// Restores data taken by [`Self::snapshot`] from a scene with the same configuration.
    /// Validates everything first; on error the scene is unchanged.
    pub fn restore(&mut self, s: &SceneSnapshot) -> Result<(), InputError> {
        let n = self.config().mounts.len();
        if s.operating_points.len() != n
            || s.inputs.stiffness_scale.len() != n
            || s.inputs.damping_scale.len() != n
        {
            return Err(InputError(format!(
                "snapshot is for a different number of mounts than {n}"
            )));
        }
        let mut trial = self.clone();
        let (c, l) = (s.inputs.crank_speed, s.inputs.load_torque);
        trial.set_crank_speed(c.since, c.value, c.rate)?;
        trial.set_load_torque(l.since, l.value, l.rate)?;
        for i in 0..n {
            trial.set_mount_scales(i, s.inputs.stiffness_scale[i], s.inputs.damping_scale[i])?;
        }
        trial.set_fade_start(s.fade_start)?;
        if trial.effects().gas_forces && s.gas_load != trial.config().gas.load {
            trial.set_gas_load(s.gas_load)?;
        }
        for (i, p) in s.operating_points.iter().enumerate() {
            if p.iter().any(|x| !x.is_finite()) {
                return Err(InputError(format!(
                    "mount {i} operating point {p:?} must be finite"
                )));
            }
        }
        trial.set_operating_points(
            &s.operating_points
                .iter()
                .map(|p| Vector3::new(p[0], p[1], p[2]))
                .collect::<Vec<_>>(),
        );
        *self = trial;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::EngineConfig;

    #[test]
    fn snapshot_round_trips_through_numbers_and_restores_the_scene() {
        let mut scene = GroundScene::new(EngineConfig::default()).expect("scene");
        scene.set_load_torque(0.0, 120.0, 0.0).expect("torque");
        scene.static_equilibrium(0.3).expect("statics");
        scene.set_crank_speed(0.4, 200.0, 15.0).expect("speed");
        scene.set_mount_scales(1, 1.3, 0.4).expect("scales");
        scene.set_gas_load(0.7).expect("load");
        let snap = scene.snapshot();
        let flat = snap.to_vec();
        assert_eq!(flat.len(), SceneSnapshot::len_for(4));
        let back = SceneSnapshot::from_slice(&flat, 4).expect("parse");
        assert_eq!(back, snap);
        let mut fresh = GroundScene::new(EngineConfig::default()).expect("scene");
        fresh.restore(&back).expect("restore");
        assert_eq!(fresh.snapshot(), snap);
        assert!(SceneSnapshot::from_slice(&flat[1..], 4).is_err());
        let mut bad = flat.clone();
        bad[3] = f64::NAN;
        assert!(SceneSnapshot::from_slice(&bad, 4).is_err());
        let mut wrong = snap.clone();
        wrong.inputs.stiffness_scale[0] = -1.0;
        let before = fresh.snapshot();
        assert!(fresh.restore(&wrong).is_err());
        assert_eq!(fresh.snapshot(), before);
    }
}
