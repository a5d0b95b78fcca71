//! From the FMU's settings and inputs to the coupled model, and from the model to the FMU's
//! outputs.

use super::settings::Replaced;
use super::{Error, Inputs, Outputs, Settings};
use crate::model::inputs::AttachmentMotion;
use crate::model::scene::build;
use crate::model::{CoupledModel, RampInput, VehicleConfig};

/// Number of mounts the FMU's variables expose (`mount[1..4]`).
pub const FMU_MOUNTS: usize = 4;

/// Body points the FMU's outputs `steeringWheel.*` and `seat.*` report.
pub const STEERING_WHEEL_POINT: &str = "steering_wheel";
/// Name of the body point (listed under `outputs` in the vehicle configuration) whose
/// acceleration is the FMU's `seat.a`.
pub const SEAT_POINT: &str = "seat_rail";

/// The vehicle the settings name (configuration file or built-in default), with the
/// [`Settings::vehicle`] overrides applied.
pub fn vehicle_config(settings: &Settings) -> Result<VehicleConfig, Error> {
    vehicle_config_with_replacements(settings).map(|(config, _)| config)
}

/// [`vehicle_config`] and the configuration values an override replaced.
pub fn vehicle_config_with_replacements(
    settings: &Settings,
) -> Result<(VehicleConfig, Vec<Replaced>), Error> {
    let mut config = match &settings.config_file {
        Some(path) => VehicleConfig::from_file(path)
            .map_err(|e| format!("configuration {}: {e}", path.display()))?,
        None => VehicleConfig::default(),
    };
    let replaced = settings
        .vehicle
        .apply(&mut config, settings.config_file.is_some());
    if config.mounts.len() > FMU_MOUNTS {
        return Err(Error::Model(format!(
            "the configuration has {} mounts; the FMU exposes {FMU_MOUNTS} (deactivate one with \"active\": false)",
            config.mounts.len()
        )));
    }
    Ok((config, replaced))
}

/// A coupled model built for the settings, with what replaced the configuration and log
/// lines on how it was built.
pub struct BuiltModel {
    /// The coupled model: engine, mounts and ground or reduced chassis.
    pub model: CoupledModel,
    /// Configuration values the FMU parameters replaced, for the log.
    pub replaced: Vec<Replaced>,
    /// Log lines on how the model was built, the last one describing the scene.
    pub notes: Vec<String>,
}

/// The coupled model the settings describe.
pub fn build_model(settings: &Settings) -> Result<BuiltModel, Error> {
    let (vehicle, replaced) = vehicle_config_with_replacements(settings)?;
    let built = build(&vehicle, settings.scene, &settings.chassis)?;
    let mut notes = built.notes;
    notes.push(format!(
        "scene {} ({}): {}",
        settings.scene.number(),
        settings.scene.describe(),
        built.model.describe()
    ));
    Ok(BuiltModel {
        model: built.model,
        replaced,
        notes,
    })
}

fn ramp(s: &super::Signal) -> RampInput {
    RampInput {
        value: s.value,
        rate: s.derivative,
        since: s.reference_time,
    }
}

/// Applies the FMU inputs to the model (validated as a whole; on error nothing changes).
pub fn apply_inputs(model: &mut CoupledModel, inputs: &Inputs) -> Result<(), Error> {
    let mut m = model.inputs().clone();
    m.crank_speed = ramp(&inputs.crank_speed);
    m.load_torque = ramp(&inputs.load_torque);
    for i in 0..m.stiffness_scale.len().min(FMU_MOUNTS) {
        m.stiffness_scale[i] = ramp(&inputs.stiffness_scale[i]);
        m.damping_scale[i] = ramp(&inputs.damping_scale[i]);
        m.body_motion[i] = AttachmentMotion {
            displacement: inputs.body_displacement[i].each_ref().map(ramp),
            velocity: inputs.body_velocity[i].each_ref().map(ramp),
        };
    }
    model.set_inputs(&m).map_err(|e| Error::Model(e.0))
}

/// The FMU outputs at `(t, y)`. Outputs without a component in this scene (the steering wheel
/// and seat on rigid ground, a mount the configuration does not have) stay zero.
pub fn outputs(model: &CoupledModel, t: f64, y: &[f64]) -> Result<Outputs, Error> {
    let o = model
        .outputs(t, y)
        .map_err(|e| Error::Model(format!("{e:?}")))?;
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
    if let Some(p) = o.point(STEERING_WHEEL_POINT) {
        out.steering_wheel_acceleration = p.acceleration;
    }
    if let Some(p) = o.point(SEAT_POINT) {
        out.seat_acceleration = p.acceleration;
    }
    Ok(out)
}
