//! From the FMU's settings and inputs to the coupled model, and from the model to the FMU's
//! outputs.

use super::settings::Replaced;
use super::{Error, Inputs, Outputs, Settings};
use crate::model::scene::build;
use crate::model::{CoupledModel, VehicleConfig};

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

/// Applies the inputs, sized to the model's mounts, to the model (checked by the model as a
/// whole; on error nothing changes), and returns them as applied.
pub fn apply_inputs(model: &mut CoupledModel, inputs: &Inputs) -> Result<Inputs, Error> {
    let sized = inputs.sized(model.mounts().len());
    model.set_inputs(&sized.model)?;
    Ok(sized)
}

/// Applies inputs, sized to the model's mounts, each of which passed its rule where it was set
/// ([`CoupledModel::check_input`]): the rules do not run again. Returns them as applied.
pub fn apply_checked_inputs(model: &mut CoupledModel, inputs: &Inputs) -> Result<Inputs, Error> {
    let sized = inputs.sized(model.mounts().len());
    model.set_checked_inputs(&sized.model)?;
    Ok(sized)
}

/// Where the FMU's comfort outputs (`steeringWheel.a`, `seat.a`) are among a model's output
/// points: resolved once when the model is built, not looked up by name at every output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ComfortPoints {
    /// Position of [`STEERING_WHEEL_POINT`] among the output points, if the model has it.
    pub steering_wheel: Option<usize>,
    /// Position of [`SEAT_POINT`].
    pub seat: Option<usize>,
}

impl ComfortPoints {
    /// The comfort points of `model`'s output points.
    pub fn of(model: &CoupledModel) -> ComfortPoints {
        ComfortPoints::resolve(model.output_points().iter().map(|p| p.name.as_str()))
    }

    /// The positions of the comfort points among output points named `names`, in order.
    pub fn resolve<'a>(names: impl Iterator<Item = &'a str> + Clone) -> ComfortPoints {
        let position = |wanted: &str| names.clone().position(|n| n == wanted);
        ComfortPoints {
            steering_wheel: position(STEERING_WHEEL_POINT),
            seat: position(SEAT_POINT),
        }
    }
}

/// The FMU outputs at `(t, y)`, the comfort points at `comfort`. Outputs without a component
/// in this scene (the steering wheel and seat on rigid ground, a mount the configuration does
/// not have) stay zero.
pub fn outputs(
    model: &CoupledModel,
    comfort: ComfortPoints,
    t: f64,
    y: &[f64],
) -> Result<Outputs, Error> {
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
    if let Some(p) = comfort.steering_wheel.and_then(|k| o.points.get(k)) {
        out.steering_wheel_acceleration = p.acceleration;
    }
    if let Some(p) = comfort.seat.and_then(|k| o.points.get(k)) {
        out.seat_acceleration = p.acceleration;
    }
    Ok(out)
}
