//! The one mapping between the FMU's variables and the runtime's typed world: parameters onto
//! [`Settings`], the Real input signals onto [`cosim::Inputs`] (through the bindings the variable
//! table generates, [`bindings::input_of`]), the model's effective values back onto parameters,
//! and the runtime's typed errors and notes into messages that name the FMU's variables. No
//! other module names an FMU variable: they use the generated constants, and the names come from
//! the generated table.

use std::path::{Path, PathBuf};

use super::bindings;
use super::input_track::InputTrack;
use super::values::Values;
use crate::cms::CacheSetting;
use crate::cosim::{
    self, BodyOption, BodyOptions, EffectSwitch, Input, Replaced, SceneKind, Settings,
    VehicleOverrides, VehicleSetting,
};
use crate::model::RampInput;
use crate::variables::{
    boolean, integer, real, string, Causality, Parameters, BOOLEANS, INTEGERS, REALS, STRINGS,
};

/// The Boolean parameter of an effect switch.
fn effect_parameter(switch: EffectSwitch) -> u32 {
    match switch {
        EffectSwitch::GasForces => boolean::EFFECT_GAS_FORCES,
        EffectSwitch::MassForces => boolean::EFFECT_MASS_FORCES,
        EffectSwitch::BalanceShaft => boolean::EFFECT_BALANCE_SHAFT,
        EffectSwitch::Gyroscopic => boolean::EFFECT_GYROSCOPIC,
        EffectSwitch::RingCarrierElasticity => boolean::EFFECT_RING_CARRIER,
        EffectSwitch::MountNonlinearity => boolean::EFFECT_MOUNT_NONLINEARITY,
        EffectSwitch::ChassisFlexibility => boolean::EFFECT_CHASSIS_FLEXIBILITY,
    }
}

/// The settings the parameters in `values` describe, with the vehicle from `config_file`.
/// Vehicle parameters the master set replace the configuration's values; the others keep them.
/// The experiment's tolerance is the relative tolerance unless the master set `solver.relTol`.
pub fn settings(
    values: &Values,
    config_file: Option<PathBuf>,
    experiment_tolerance: Option<f64>,
) -> Result<Settings, String> {
    let (r, i, b, s) = (
        &values.reals,
        &values.integers,
        &values.booleans,
        &values.strings,
    );
    let p = Parameters::from_values(r.as_slice(), i.as_slice(), b.as_slice(), s.as_slice());
    let scene = SceneKind::from_number(p.scene)
        .map_err(|m| format!("{}: {m}", INTEGERS[integer::SCENE as usize].name))?;
    let given = |index: u32| r.set_by_master(index).then(|| *r.get(index));
    let mut vehicle = VehicleOverrides {
        gas_load: given(real::ENGINE_LOAD),
        fade_in_time: given(real::FADE_IN_TIME),
        crank_start_angle: given(real::CRANK_START_ANGLE),
        speed_time_constant: given(real::CRANK_SPEED_TIME_CONSTANT),
        ..VehicleOverrides::default()
    };
    for switch in EffectSwitch::ALL {
        let index = effect_parameter(switch);
        if b.set_by_master(index) {
            vehicle.effects.set(switch, *b.get(index));
        }
    }
    let rel_tol = match (experiment_tolerance, r.set_by_master(real::SOLVER_REL_TOL)) {
        (Some(tolerance), false) => tolerance,
        _ => p.solver_rel_tol,
    };
    let count = |index: u32, value: i32| {
        usize::try_from(value)
            .map_err(|_| format!("{} = {value} must be >= 0", INTEGERS[index as usize].name))
    };
    Ok(Settings {
        scene,
        config_file,
        vehicle,
        rel_tol,
        abs_tol: p.solver_abs_tol,
        max_order: count(integer::SOLVER_MAX_ORDER, p.solver_max_order)?,
        stability_limit_detection: p.solver_stability_limit_detection,
        periodic_start: p.initialization_periodic,
        chassis: BodyOptions {
            mode_cutoff_hz: p.chassis_mode_cutoff,
            max_modes: count(integer::CHASSIS_MAX_MODES, p.chassis_max_modes)?,
            max_rpm: p.scene_max_rpm,
            max_engine_order: p.scene_max_engine_order,
            interface_rotations: p.chassis_interface_rotations,
            modal_damping_scale: p.chassis_modal_damping_scale,
            stiffening_bar: p.chassis_stiffening_bar,
            stiff_front_plate: p.chassis_stiff_front_plate,
            cache: match (p.chassis_cache_enabled, p.chassis_cache_dir.trim()) {
                (false, _) => CacheSetting::Disabled,
                (true, "") => CacheSetting::Default,
                (true, dir) => CacheSetting::Dir(PathBuf::from(dir)),
            },
        },
        export: match p.analysis_export_folder.trim() {
            "" if p.analysis_full_recovery => {
                return Err(format!(
                    "{} = true needs {}: the folder to write the shapes to",
                    BOOLEANS[boolean::ANALYSIS_FULL_RECOVERY as usize].name,
                    STRINGS[string::ANALYSIS_EXPORT_FOLDER as usize].name
                ))
            }
            "" => None,
            folder => Some(cosim::ExportRequest {
                folder: PathBuf::from(folder),
                full_recovery: p.analysis_full_recovery,
            }),
        },
    })
}

/// The vehicle configuration `configFile` names: relative to the FMU's resources, or the
/// FMU's own `vehicle.json` when empty (missing from an unpacked FMU is an error, not a silent
/// switch to the built-in data); the built-in vehicle when there are no resources.
pub fn config_file(
    values: &Values,
    resource_dir: Option<&Path>,
) -> Result<Option<PathBuf>, String> {
    let given = values.strings.get(string::CONFIG_FILE).trim();
    if !given.is_empty() {
        let path = PathBuf::from(given);
        return Ok(Some(match resource_dir {
            Some(r) if path.is_relative() => r.join(path),
            _ => path,
        }));
    }
    let Some(r) = resource_dir else {
        return Ok(None);
    };
    let path = r.join(cosim::DEFAULT_CONFIG_NAME);
    if !path.is_file() {
        return Err(format!(
            "the FMU's resources {} have no {} ({} is empty)",
            r.display(),
            cosim::DEFAULT_CONFIG_NAME,
            crate::variables::STRINGS[string::CONFIG_FILE as usize].name
        ));
    }
    Ok(Some(path))
}

/// Where the tolerances come from, for the log; `setup` names the function that set up the
/// experiment.
pub fn tolerance_note(
    values: &Values,
    settings: &Settings,
    experiment: Option<f64>,
    setup: &str,
) -> String {
    let name = REALS[real::SOLVER_REL_TOL as usize].name;
    let absolute = REALS[real::SOLVER_ABS_TOL as usize].name;
    let absolute = if settings.abs_tol > 0.0 {
        format!("; {absolute} = {} for every state", settings.abs_tol)
    } else {
        format!("; {absolute} = 0: the absolute tolerance follows the relative one")
    };
    let relative = match (experiment, values.reals.set_by_master(real::SOLVER_REL_TOL)) {
        (Some(t), false) => format!("relative tolerance {t} from {setup}"),
        (Some(t), true) => format!(
            "relative tolerance {} from {name} (set explicitly; {setup}'s {t} not used)",
            settings.rel_tol
        ),
        (None, _) => format!("relative tolerance {} ({name})", settings.rel_tol),
    };
    relative + &absolute
}

/// The parameters the vehicle values come from, set to the values the model uses (a
/// configuration file's where the master did not set them), so that reading one tells the truth.
pub fn write_effective_parameters(values: &mut Values, runtime: &cosim::Runtime) {
    let Some(simulation) = runtime.engine() else {
        // The body FMU's parameters are all the model's own (nothing comes from the engine).
        return;
    };
    let model = simulation.model();
    let engine = model.powertrain().config();
    let r = &mut values.reals;
    r.put(real::ENGINE_LOAD, engine.gas.load);
    r.put(real::FADE_IN_TIME, engine.excitation_fade_in);
    r.put(
        real::CRANK_START_ANGLE,
        engine.start_crank_angle_deg.to_radians(),
    );
    r.put(
        real::CRANK_SPEED_TIME_CONSTANT,
        model.follower().time_constant,
    );
    for (slots, deflection) in real::MOUNT_STATIC_DEFLECTION
        .iter()
        .zip(model.operating_points())
    {
        for (&slot, d) in slots.iter().zip(deflection) {
            r.put(slot, d);
        }
    }
    let effects = model.effects();
    for switch in EffectSwitch::ALL {
        values
            .booleans
            .put(effect_parameter(switch), effects.get(switch));
    }
}

/// The calculated parameters that follow from the parameters alone, written when one is read so
/// that reading them builds no model: the chassis mode cut-off in use.
pub fn write_derived_parameters(values: &mut Values) -> Result<(), String> {
    let cutoff = settings(values, None, None)?.chassis.cutoff_hz();
    values.reals.put(real::CHASSIS_MODE_CUTOFF_IN_USE, cutoff);
    Ok(())
}

/// What a calculated parameter needs before it can be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Calculated {
    /// The parameters alone ([`write_derived_parameters`]).
    FromParameters,
    /// The model built at its starting point ([`write_effective_parameters`]).
    FromModel,
    /// The natural modes of the model linearised at its static equilibrium.
    NaturalModes,
}

/// What the calculated parameter with value reference `vr` needs.
pub fn calculated(vr: u32) -> Calculated {
    let is = |index: u32| REALS[index as usize].vr == vr;
    if is(real::CHASSIS_MODE_CUTOFF_IN_USE) {
        Calculated::FromParameters
    } else if real::MOUNT_STATIC_DEFLECTION
        .iter()
        .flatten()
        .any(|&i| is(i))
    {
        Calculated::FromModel
    } else {
        Calculated::NaturalModes
    }
}

/// The runtime's inputs from the Real input signals, from `time` on (SI units), one entry per
/// mount of the FMU's variables (the runtime sizes them to the configuration).
pub fn inputs_from(tracks: &[InputTrack], time: f64) -> cosim::Inputs {
    inputs_by(|index, to_si| signal(&tracks[index as usize], time, to_si))
}

/// The runtime input Real `index` is, with the signal `tracks` give it from `time` on (SI
/// units): what a value or derivative the master sets is checked as. `None` for a Real that is
/// not an input.
pub fn input_at(tracks: &[InputTrack], index: u32, time: f64) -> Option<(Input, RampInput)> {
    let (input, to_si) = bindings::input_of(index)?;
    Some((input, signal(&tracks[index as usize], time, to_si)))
}

/// The signal of `track` from `time` on, converted to SI units by `to_si`: the one conversion
/// of an input's value and derivative.
fn signal(track: &InputTrack, time: f64, to_si: f64) -> RampInput {
    let (value, derivative) = track.preview(time);
    RampInput {
        value: value * to_si,
        rate: derivative * to_si,
        since: time,
    }
}

/// Input increments as runtime inputs (SI units, values only), from increments `seeds` of the
/// Reals indexed like [`REALS`]: the seed of a directional derivative.
pub fn input_increments(seeds: &[f64]) -> cosim::Inputs {
    inputs_by(|index, to_si| RampInput::constant(seeds[index as usize] * to_si))
}

/// The runtime's inputs with each ramp from `ramp(real index, factor to SI)`, each Real input
/// in the slot its row of the variable table binds it to ([`bindings::input_of`]); the slots no
/// variable has stay nominal.
fn inputs_by(ramp: impl Fn(u32, f64) -> RampInput) -> cosim::Inputs {
    let mut inputs = cosim::Inputs::nominal(cosim::FMU_MOUNTS);
    for v in REALS.iter().filter(|v| v.causality == Causality::Input) {
        let Some((input, to_si)) = bindings::input_of(v.index) else {
            continue;
        };
        if let Some(slot) = inputs.ramp_mut(input) {
            *slot = ramp(v.index, to_si);
        }
    }
    inputs
}

/// Whether Real `index` is the motion of an external body's point at a mount (`mount[i].body.*`),
/// which only scene 3 uses.
pub fn is_body_point_input(index: usize) -> bool {
    u32::try_from(index)
        .ok()
        .and_then(bindings::input_of)
        .is_some_and(|(input, _)| input.is_external_body_motion())
}

/// The warning for body-point inputs set while `scene` is not the one with an external body,
/// naming the first input set (`None` if the scene uses them).
pub fn unused_body_point_input(values: &Values, index: usize) -> Option<String> {
    let scene = *values.integers.get(integer::SCENE);
    if scene == SceneKind::ExternalBody.number() {
        return None;
    }
    Some(format!(
        "{} is the motion of an external body's point at a mount, used in {} = {} only; \
         {} = {scene} ignores it (said once per instance)",
        REALS[index].name,
        INTEGERS[integer::SCENE as usize].name,
        SceneKind::ExternalBody.number(),
        INTEGERS[integer::SCENE as usize].name,
    ))
}

/// The FMU parameter behind a body option.
fn body_option_name(option: BodyOption) -> &'static str {
    let real = |i: u32| REALS[i as usize].name;
    let boolean = |i: u32| BOOLEANS[i as usize].name;
    match option {
        BodyOption::ModeCutoff => real(real::CHASSIS_MODE_CUTOFF),
        BodyOption::MaxModes => INTEGERS[integer::CHASSIS_MAX_MODES as usize].name,
        BodyOption::MaxRpm => real(real::SCENE_MAX_RPM),
        BodyOption::MaxEngineOrder => real(real::SCENE_MAX_ENGINE_ORDER),
        BodyOption::InterfaceRotations => boolean(boolean::CHASSIS_INTERFACE_ROTATIONS),
        BodyOption::ModalDampingScale => real(real::CHASSIS_MODAL_DAMPING_SCALE),
        BodyOption::StiffeningBar => boolean(boolean::CHASSIS_STIFFENING_BAR),
        BodyOption::StiffFrontPlate => boolean(boolean::CHASSIS_STIFF_FRONT_PLATE),
        BodyOption::Cache => boolean(boolean::CHASSIS_CACHE_ENABLED),
    }
}

/// The FMU parameter behind a vehicle value.
fn vehicle_setting_name(setting: VehicleSetting) -> &'static str {
    let real = match setting {
        VehicleSetting::Effect(switch) => return BOOLEANS[effect_parameter(switch) as usize].name,
        VehicleSetting::GasLoad => real::ENGINE_LOAD,
        VehicleSetting::FadeInTime => real::FADE_IN_TIME,
        VehicleSetting::CrankStartAngle => real::CRANK_START_ANGLE,
        VehicleSetting::SpeedTimeConstant => real::CRANK_SPEED_TIME_CONSTANT,
    };
    REALS[real as usize].name
}

/// A runtime error as the FMU's user reads it: parameters and inputs by their FMU names and
/// units.
pub fn message(error: &cosim::Error) -> String {
    match error {
        cosim::Error::BodyOption {
            option,
            value,
            rule,
        } => format!("{} = {value} {rule}", body_option_name(*option)),
        cosim::Error::Input { input, value, rule } => match bindings::input_variable(*input) {
            Some((index, scale)) => format!(
                "{} = {} {rule}",
                REALS[index as usize].name,
                super::values::Num(value * scale)
            ),
            None => error.to_string(),
        },
        cosim::Error::Model(m) => m.clone(),
    }
}

/// A configuration value a parameter replaced, for the log.
pub fn replaced_note(r: &Replaced) -> String {
    format!(
        "{} = {} (FMU parameter) replaces the configuration's {}",
        vehicle_setting_name(r.setting),
        r.value,
        r.configured
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Effects, SpeedFollower, VehicleConfig};
    use crate::variables::units;

    /// The model's own defaults are the variable table's start values: one set of defaults.
    #[test]
    fn start_values_are_the_model_defaults() {
        let start = Values::start();
        assert_eq!(
            settings(&start, None, None).unwrap(),
            Settings::default(),
            "settings"
        );
        let v = VehicleConfig::default();
        let r = &start.reals;
        assert_eq!(*r.get(real::ENGINE_LOAD), v.engine.gas.load);
        assert_eq!(*r.get(real::FADE_IN_TIME), v.engine.excitation_fade_in);
        assert_eq!(
            *r.get(real::CRANK_START_ANGLE),
            v.engine.start_crank_angle_deg.to_radians()
        );
        assert_eq!(
            *r.get(real::CRANK_SPEED_TIME_CONSTANT),
            SpeedFollower::default().time_constant
        );
        assert_eq!(v.speed_follower, SpeedFollower::default());
        assert_eq!(v.effects, Effects::default());
        for switch in EffectSwitch::ALL {
            assert_eq!(
                *start.booleans.get(effect_parameter(switch)),
                Effects::default().get(switch),
                "{switch:?}"
            );
        }
    }

    #[test]
    fn only_what_the_master_set_overrides_the_configuration() {
        let mut values = Values::start();
        values.reals = values
            .reals
            .with_set(&[real::ENGINE_LOAD as usize], &[0.5], |_| Ok(()))
            .unwrap();
        values.booleans = values
            .booleans
            .with_set(&[boolean::EFFECT_GYROSCOPIC as usize], &[false], |_| Ok(()))
            .unwrap();
        let s = settings(&values, None, Some(1e-7)).unwrap();
        assert_eq!(s.vehicle.gas_load, Some(0.5));
        assert_eq!(s.vehicle.fade_in_time, None);
        assert_eq!(s.vehicle.effects.get(EffectSwitch::Gyroscopic), Some(false));
        assert_eq!(s.vehicle.effects.get(EffectSwitch::GasForces), None);
        assert_eq!(s.rel_tol, 1e-7, "the experiment's tolerance");
        values.reals = values
            .reals
            .with_set(&[real::SOLVER_REL_TOL as usize], &[1e-4], |_| Ok(()))
            .unwrap();
        let s = settings(&values, None, Some(1e-7)).unwrap();
        assert_eq!(s.rel_tol, 1e-4, "solver.relTol set by the master wins");
    }

    #[test]
    fn messages_name_the_fmu_variables() {
        let e = cosim::Error::Input {
            input: Input::CrankSpeed,
            value: -100.0 * units::RPM,
            rule: "is negative".into(),
        };
        let m = message(&e);
        assert!(
            m.starts_with("rpm = -100") && m.ends_with("is negative"),
            "{m}"
        );
        let e = cosim::Error::Input {
            input: Input::StiffnessScale(2),
            value: -1.0,
            rule: "must be >= 0".into(),
        };
        assert_eq!(message(&e), "mount[3].stiffnessScale = -1 must be >= 0");
        let e: cosim::Error = BodyOptions {
            mode_cutoff_hz: -1.0,
            ..BodyOptions::default()
        }
        .validate()
        .unwrap_err()
        .into();
        assert!(
            message(&e).starts_with("chassis.modeCutoff = -1 Hz"),
            "{}",
            message(&e)
        );
        for (setting, name) in [
            (VehicleSetting::GasLoad, "engine.load"),
            (VehicleSetting::CrankStartAngle, "crank.startAngle"),
            (
                VehicleSetting::Effect(EffectSwitch::ChassisFlexibility),
                "effects.chassisFlexibility",
            ),
        ] {
            assert_eq!(vehicle_setting_name(setting), name);
        }
        for switch in EffectSwitch::ALL {
            assert!(vehicle_setting_name(VehicleSetting::Effect(switch)).starts_with("effects."));
        }
    }
}
