//! From the FMU's settings and inputs to the coupled model, and from the model to the FMU's
//! outputs.

use super::{Inputs, Outputs, Settings};
use crate::model::scene::{build, SceneKind};
use crate::model::{CoupledModel, RampInput, VehicleConfig};

/// Number of mounts the FMU's variables expose (`mount[1..4]`).
pub const FMU_MOUNTS: usize = 4;

/// Body points the FMU's outputs `steeringWheel.*` and `seat.*` report.
pub const STEERING_WHEEL_POINT: &str = "steering_wheel";
pub const SEAT_POINT: &str = "seat_rail";

/// The vehicle the settings name (configuration file or built-in default), with the FMU
/// parameters applied on top by the precedence rule of [`Settings::explicit`].
pub fn vehicle_config(settings: &Settings) -> Result<VehicleConfig, String> {
    vehicle_config_with_notes(settings).map(|(config, _)| config)
}

/// [`vehicle_config`] and a log line per configuration value an FMU parameter replaced.
pub fn vehicle_config_with_notes(
    settings: &Settings,
) -> Result<(VehicleConfig, Vec<String>), String> {
    let mut config = match &settings.config_file {
        Some(path) => VehicleConfig::from_file(path)
            .map_err(|e| format!("configuration {}: {e}", path.display()))?,
        None => VehicleConfig::default(),
    };
    let mut notes = Vec::new();
    let applies = |name: &str| {
        settings
            .explicit
            .as_ref()
            .is_none_or(|set| set.contains(name))
    };
    let mut apply = |name: &str, slot: &mut f64, value: f64| {
        if applies(name) {
            if settings.config_file.is_some() && *slot != value {
                notes.push(format!(
                    "{name} = {value} (FMU parameter) replaces the configuration's {}",
                    *slot
                ));
            }
            *slot = value;
        }
    };
    apply(
        "engine.load",
        &mut config.engine.gas.load,
        settings.gas_load,
    );
    apply(
        "excitation.fadeInTime",
        &mut config.engine.excitation_fade_in,
        settings.fade_in_time,
    );
    apply(
        "crank.startAngle",
        &mut config.engine.start_crank_angle_deg,
        settings.crank_start_angle.to_degrees(),
    );
    apply(
        "crank.speedTimeConstant",
        &mut config.speed_follower.time_constant,
        settings.speed_time_constant,
    );
    let e = &settings.effects;
    let c = &mut config.effects;
    for (name, slot, value) in [
        ("effects.gasForces", &mut c.gas_forces, e.gas_forces),
        ("effects.massForces", &mut c.mass_forces, e.mass_forces),
        (
            "effects.balanceShaft",
            &mut c.balance_shaft,
            e.balance_shaft,
        ),
        ("effects.gyroscopic", &mut c.gyroscopic, e.gyroscopic),
        (
            "effects.ringCarrier",
            &mut c.ring_carrier_elasticity,
            e.ring_carrier_elasticity,
        ),
        (
            "effects.mountNonlinearity",
            &mut c.mount_nonlinearity,
            e.mount_nonlinearity,
        ),
        (
            "effects.chassisFlexibility",
            &mut c.chassis_flexibility,
            e.chassis_flexibility,
        ),
    ] {
        if applies(name) {
            if settings.config_file.is_some() && *slot != value {
                notes.push(format!(
                    "{name} = {value} (FMU parameter) replaces the configuration's {}",
                    *slot
                ));
            }
            *slot = value;
        }
    }
    if config.mounts.len() > FMU_MOUNTS {
        return Err(format!(
            "the configuration has {} mounts; the FMU exposes {FMU_MOUNTS} (deactivate one with \"active\": false)",
            config.mounts.len()
        ));
    }
    Ok((config, notes))
}

/// The coupled model the settings describe, with log lines on how it was built.
pub fn build_model(settings: &Settings) -> Result<(CoupledModel, Vec<String>), String> {
    let kind = match settings.scene {
        1 => SceneKind::Ground,
        2 => SceneKind::Body,
        other => {
            return Err(format!(
                "scene {other} is not available (1 = engine on rigid ground, 2 = engine in the elastic chassis)"
            ))
        }
    };
    let (vehicle, mut notes) = vehicle_config_with_notes(settings)?;
    let built = build(&vehicle, kind, &settings.chassis)?;
    notes.extend(built.notes);
    notes.push(format!(
        "scene {} ({}): {}",
        settings.scene,
        match kind {
            SceneKind::Ground => "engine on rigid ground",
            SceneKind::Body => "engine in the elastic chassis",
        },
        built.model.describe()
    ));
    Ok((built.model, notes))
}

fn ramp(s: &super::Signal) -> RampInput {
    RampInput {
        value: s.value,
        rate: s.derivative,
        since: s.reference_time,
    }
}

/// Applies the FMU inputs to the model (validated as a whole; on error nothing changes).
pub fn apply_inputs(model: &mut CoupledModel, inputs: &Inputs) -> Result<(), String> {
    let mut m = model.inputs().clone();
    m.crank_speed = ramp(&inputs.crank_speed);
    m.load_torque = ramp(&inputs.load_torque);
    for i in 0..m.stiffness_scale.len().min(FMU_MOUNTS) {
        m.stiffness_scale[i] = ramp(&inputs.stiffness_scale[i]);
        m.damping_scale[i] = ramp(&inputs.damping_scale[i]);
    }
    model.set_inputs(&m).map_err(|e| e.0)
}

/// The FMU outputs at `(t, y)`. Outputs without a component in this scene (the steering wheel
/// and seat on rigid ground, a mount the configuration does not have) stay zero.
pub fn outputs(model: &CoupledModel, t: f64, y: &[f64]) -> Result<Outputs, String> {
    let o = model.outputs(t, y).map_err(|e| format!("{e:?}"))?;
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
