//! What a simulation is built from: the scene, the vehicle configuration with the values that
//! replace some of its entries, the integrator's accuracy and the body's reduction.

use std::path::PathBuf;

use crate::model::scene::{BodyOptions, SceneKind};
use crate::model::{EffectSwitch, VehicleConfig};

/// Everything fixed at initialisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Engine on rigid ground, or in the elastic body.
    pub scene: SceneKind,
    /// Vehicle configuration JSON; `None` = built-in defaults.
    pub config_file: Option<PathBuf>,
    /// Values that replace the vehicle configuration's; `None` keeps the configuration's.
    pub vehicle: VehicleOverrides,
    /// Relative tolerance of the integrator.
    pub rel_tol: f64,
    /// Absolute tolerance of the integrator: 0 follows `rel_tol` (`atol_i = rel_tol ·
    /// nominal_i` per state, [`crate::model::CoupledModel::state_nominals`]); > 0 is one
    /// absolute tolerance for every state, in state units.
    pub abs_tol: f64,
    /// Highest BDF order (1..=5).
    pub max_order: usize,
    /// Hold the order down where lightly damped modes make high orders unstable.
    pub stability_limit_detection: bool,
    /// Start on the periodic steady state at the start inputs ([`super::periodic`]) instead of
    /// the static equilibrium with a fade-in.
    pub periodic_start: bool,
    /// Used by the elastic-body scene only.
    pub chassis: BodyOptions,
    /// Write the modal data and the linearised model for the analyses at initialisation
    /// ([`super::export`]).
    pub export: Option<ExportRequest>,
}

impl Default for Settings {
    /// The built-in vehicle on rigid ground at rtol 1e-5.
    fn default() -> Self {
        Settings {
            scene: SceneKind::Ground,
            config_file: None,
            vehicle: VehicleOverrides::default(),
            rel_tol: 1e-5,
            abs_tol: 0.0,
            max_order: 5,
            stability_limit_detection: true,
            periodic_start: false,
            chassis: BodyOptions::default(),
            export: None,
        }
    }
}

/// Vehicle values given beside the configuration; each one set replaces the configuration's.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VehicleOverrides {
    /// Combustion load, 0 = idle … 1 = full load.
    pub gas_load: Option<f64>,
    /// Smooth fade-in of the engine excitation, s.
    pub fade_in_time: Option<f64>,
    /// Crank angle at the start time, rad.
    pub crank_start_angle: Option<f64>,
    /// Time constant with which the crank speed follows its set-point, s.
    pub speed_time_constant: Option<f64>,
    /// Effect switches.
    pub effects: EffectOverrides,
}

/// Effect switches given beside the configuration, one `Option` per switch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EffectOverrides([Option<bool>; 7]);

impl EffectOverrides {
    /// Every switch as in `effects`.
    pub fn all(effects: crate::model::Effects) -> Self {
        EffectOverrides(EffectSwitch::ALL.map(|s| Some(effects.get(s))))
    }

    /// The value given for `switch`, if any.
    pub fn get(&self, switch: EffectSwitch) -> Option<bool> {
        self.0[switch as usize]
    }

    /// Gives `switch` the value `on`.
    pub fn set(&mut self, switch: EffectSwitch, on: bool) {
        self.0[switch as usize] = Some(on);
    }
}

/// A vehicle value that [`VehicleOverrides`] can replace.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VehicleSetting {
    /// The combustion load between idle (0) and full load (1), `engine.gas.load`.
    GasLoad,
    /// Time in s over which the excitation fades in, `engine.excitation_fade_in`.
    FadeInTime,
    /// Crank angle at the start time, `engine.start_crank_angle_deg` (degrees in the
    /// configuration, radians as an FMU parameter).
    CrankStartAngle,
    /// Time constant in s with which the crank speed follows its set-point.
    SpeedTimeConstant,
    /// One of the model's effect switches.
    Effect(EffectSwitch),
}

/// A configuration value that an override replaced (for the log).
#[derive(Debug, Clone, PartialEq)]
pub struct Replaced {
    /// Which value was replaced.
    pub setting: VehicleSetting,
    /// The configuration's value, in the configuration's units.
    pub configured: String,
    /// The value used instead, in the configuration's units.
    pub value: String,
}

impl VehicleOverrides {
    /// These overrides with the effect `switch` set to `on`.
    pub fn with_effect(mut self, switch: EffectSwitch, on: bool) -> Self {
        self.effects.set(switch, on);
        self
    }

    /// Applies the overrides to `config`; with `report`, lists the values that differed.
    pub fn apply(&self, config: &mut VehicleConfig, report: bool) -> Vec<Replaced> {
        let mut replaced = Vec::new();
        let mut note = |setting, configured: String, value: String| {
            if report && configured != value {
                replaced.push(Replaced {
                    setting,
                    configured,
                    value,
                });
            }
        };
        let reals = [
            (
                VehicleSetting::GasLoad,
                self.gas_load,
                &mut config.engine.gas.load,
            ),
            (
                VehicleSetting::FadeInTime,
                self.fade_in_time,
                &mut config.engine.excitation_fade_in,
            ),
            (
                VehicleSetting::CrankStartAngle,
                self.crank_start_angle.map(f64::to_degrees),
                &mut config.engine.start_crank_angle_deg,
            ),
            (
                VehicleSetting::SpeedTimeConstant,
                self.speed_time_constant,
                &mut config.speed_follower.time_constant,
            ),
        ];
        for (setting, given, slot) in reals {
            if let Some(value) = given {
                note(setting, slot.to_string(), value.to_string());
                *slot = value;
            }
        }
        for switch in EffectSwitch::ALL {
            if let Some(on) = self.effects.get(switch) {
                let configured = config.effects.get(switch);
                note(
                    VehicleSetting::Effect(switch),
                    configured.to_string(),
                    on.to_string(),
                );
                config.effects.set(switch, on);
            }
        }
        replaced
    }
}

/// What an instance writes for the analyses at initialisation ([`super::export`]): where, and
/// what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExportRequest {
    /// The folder.
    pub folder: PathBuf,
    /// Also recover the body's modes on every node (`mesh.json`, `shapes.npy`).
    pub full_recovery: bool,
}
