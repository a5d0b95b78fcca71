//! The scenes the FMU can simulate, behind one type the runtime steps.

use faer::MatMut;

use super::{Inputs, Outputs, Settings};
use crate::cms::{reduce_cached, CacheOutcome};
use crate::model::hybrid_chassis::reduction_spec;
use crate::model::{EngineConfig, EngineOutputs, GroundScene, HybridScene};
use crate::ode::{
    BlockLowRankJacobian, BlockLowRankShape, JacobianPattern, OdeProblem, ProblemError,
};

/// Number of mounts the FMU's variables expose (`mount[1..4]`).
pub const FMU_MOUNTS: usize = 4;

/// With chassis flexibility off, the chassis modes kept: the rigid-body modes on the suspension
/// (1–5 Hz; the first elastic mode is above 20 Hz).
const RIGID_CHASSIS_HZ: f64 = 10.0;

/// A model the runtime can integrate. An enum rather than a trait object: scenes are cloned for
/// FMU states and the set is closed.
#[derive(Clone)]
pub enum Scene {
    /// Engine on rigid ground (paper Table 1, left column).
    Ground(GroundScene),
    /// Engine in the elastic chassis (paper Table 1, middle column), with a log line on how the
    /// reduced chassis was obtained.
    Hybrid(HybridScene, String),
}

/// The reduced chassis scene 2 asks for, from the cache or freshly reduced (timed for the log).
fn hybrid_scene(settings: &Settings, engine: GroundScene) -> Result<Scene, String> {
    let c = &settings.chassis;
    let max_modes = usize::try_from(c.max_modes).map_err(|_| {
        format!(
            "chassis.maxModes = {} must be >= 0 (0: select by chassis.modeCutoff)",
            c.max_modes
        )
    })?;
    if !(c.mode_cutoff_hz.is_finite() && c.mode_cutoff_hz >= 0.0) {
        return Err(format!(
            "chassis.modeCutoff = {} Hz must be >= 0 and finite (0: automatic)",
            c.mode_cutoff_hz
        ));
    }
    if !(c.max_rpm > 0.0 && c.max_engine_order > 0.0 && c.cutoff_hz().is_finite()) {
        return Err(format!(
            "scene.maxRpm = {} and scene.maxEngineOrder = {} must be positive",
            c.max_rpm, c.max_engine_order
        ));
    }
    let flexible = settings.effects.chassis_flexibility;
    // A rigid chassis needs no fixed-interface modes: the constraint modes alone contain its
    // rigid-body motion on the suspension, the only part kept below.
    let (cutoff, max_modes) = if flexible {
        (c.cutoff_hz(), max_modes)
    } else {
        (1.0, 0)
    };
    let cutoff_origin = if !flexible {
        "rigid chassis: rigid-body modes on the suspension only".to_owned()
    } else if max_modes > 0 {
        format!("{max_modes} fixed-interface modes")
    } else if c.mode_cutoff_hz > 0.0 {
        format!("cut-off {cutoff:.0} Hz (chassis.modeCutoff)")
    } else {
        format!(
            "automatic cut-off {cutoff:.0} Hz = {} rpm / 60 x order {} x margin {}",
            c.max_rpm,
            c.max_engine_order,
            super::AUTO_CUTOFF_MARGIN
        )
    };
    let mut spec = reduction_spec(cutoff, max_modes, c.stiffening_bar);
    if c.interface_rotations {
        spec.interface_dofs = crate::cms::InterfaceDofs::All;
    }
    let started = std::time::Instant::now();
    let (chassis, outcome) =
        reduce_cached(&spec, &c.cache).map_err(|e| format!("chassis reduction: {e}"))?;
    let seconds = started.elapsed().as_secs_f64();
    let source = match outcome {
        CacheOutcome::Hit(path) => format!("read from cache {}", path.display()),
        CacheOutcome::Stored(path) => format!("reduced and cached at {}", path.display()),
        CacheOutcome::Replaced { path, reason } => {
            format!(
                "reduced and cached at {} (old entry: {reason})",
                path.display()
            )
        }
        CacheOutcome::NotStored { reason } => format!("reduced (not cached: {reason})"),
        CacheOutcome::Disabled => "reduced (caching disabled)".to_owned(),
    };
    let chassis = if flexible {
        chassis
    } else {
        chassis.keep_below(RIGID_CHASSIS_HZ)
    };
    let note = format!(
        "chassis (Craig-Bampton, {cutoff_origin}, stiffening bar {}, modal damping x{}): {} modes, {:.1}..{:.1} Hz, {source} in {seconds:.2} s",
        if c.stiffening_bar { "on" } else { "off" },
        c.modal_damping_scale,
        chassis.n_modes(),
        chassis.omega.first().copied().unwrap_or(0.0) / (2.0 * std::f64::consts::PI),
        chassis.omega.last().copied().unwrap_or(0.0) / (2.0 * std::f64::consts::PI),
    );
    let scene = HybridScene::new(engine, chassis).map_err(|e| e.to_string())?;
    Ok(Scene::Hybrid(scene, note))
}

/// Applies the FMU inputs to the engine model.
fn apply_inputs(g: &mut GroundScene, inputs: &Inputs) -> Result<(), String> {
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

/// The FMU outputs the engine outputs carry.
fn engine_outputs(o: &EngineOutputs) -> Outputs {
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
    out
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
    config.gas.load = settings.gas_load;
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
            2 => {
                let config = engine_config(settings)?;
                let engine = GroundScene::new(config).map_err(|e| e.to_string())?;
                hybrid_scene(settings, engine)
            }
            other => Err(format!(
                "scene {other} is not available (1 = engine on rigid ground, 2 = engine in the elastic chassis)"
            )),
        }
    }

    pub fn set_inputs(&mut self, inputs: &Inputs) -> Result<(), String> {
        match self {
            Scene::Ground(g) => apply_inputs(g, inputs),
            Scene::Hybrid(h, _) => apply_inputs(h.engine_mut(), inputs),
        }
    }

    /// Per state, the largest magnitude the integrator's relative tolerance applies to: one
    /// revolution for the cumulative crank angle (its phase is what must stay accurate), no cap
    /// elsewhere.
    pub fn magnitude_caps(&self) -> Vec<f64> {
        let mut caps = vec![f64::INFINITY; self.dim()];
        match self {
            Scene::Ground(g) => caps[g.crank_index()] = 2.0 * std::f64::consts::PI,
            // The hybrid state starts with the engine's, crank angle included.
            Scene::Hybrid(h, _) => caps[h.engine().crank_index()] = 2.0 * std::f64::consts::PI,
        }
        caps
    }

    /// The static equilibrium under the current inputs; the excitation fades in from `t0`.
    pub fn initial_state(&mut self, t0: f64) -> Result<Vec<f64>, String> {
        match self {
            Scene::Ground(g) => g.static_equilibrium(t0).map_err(|e| e.to_string()),
            Scene::Hybrid(h, _) => h.static_equilibrium(t0).map_err(|e| e.to_string()),
        }
    }

    pub fn outputs(&self, t: f64, y: &[f64]) -> Result<Outputs, String> {
        match self {
            Scene::Ground(g) => {
                let o = g.outputs(t, y).map_err(|e| format!("{e:?}"))?;
                Ok(engine_outputs(&o))
            }
            Scene::Hybrid(h, _) => {
                let o = h.outputs(t, y).map_err(|e| format!("{e:?}"))?;
                Ok(Outputs {
                    steering_wheel_acceleration: o.steering_wheel_acceleration,
                    seat_acceleration: o.seat_acceleration,
                    ..engine_outputs(&o.engine)
                })
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
            Scene::Hybrid(h, note) => {
                let c = h.engine().config();
                let active = c.mounts.iter().filter(|m| m.active).count();
                vec![
                    note.clone(),
                    format!(
                        "scene 2 (engine in the elastic chassis): {} bodies, {active} of {} mounts active, {} chassis modes, {} states; effects {:?}",
                        h.engine().body_count(),
                        c.mounts.len(),
                        h.modes_count(),
                        h.dim(),
                        c.effects
                    ),
                ]
            }
        }
    }
}

impl OdeProblem for Scene {
    fn dim(&self) -> usize {
        match self {
            Scene::Ground(g) => g.dim(),
            Scene::Hybrid(h, _) => h.dim(),
        }
    }

    fn rhs(&mut self, t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        match self {
            Scene::Ground(g) => g.rhs(t, y, f),
            Scene::Hybrid(h, _) => h.rhs(t, y, f),
        }
    }

    fn has_mass_matrix(&self) -> bool {
        match self {
            Scene::Ground(g) => g.has_mass_matrix(),
            Scene::Hybrid(h, _) => h.has_mass_matrix(),
        }
    }

    fn mass(&mut self, t: f64, y: &[f64], m: MatMut<'_, f64>) -> Result<(), ProblemError> {
        match self {
            Scene::Ground(g) => g.mass(t, y, m),
            Scene::Hybrid(h, _) => h.mass(t, y, m),
        }
    }

    fn jacobian(&mut self, t: f64, y: &[f64], j: MatMut<'_, f64>) -> Result<bool, ProblemError> {
        match self {
            Scene::Ground(g) => g.jacobian(t, y, j),
            Scene::Hybrid(h, _) => h.jacobian(t, y, j),
        }
    }

    fn jacobian_structure(&self) -> Option<BlockLowRankShape> {
        match self {
            Scene::Ground(g) => g.jacobian_structure(),
            Scene::Hybrid(h, _) => h.jacobian_structure(),
        }
    }

    fn structured_jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        j: &mut BlockLowRankJacobian,
    ) -> Result<(), ProblemError> {
        match self {
            Scene::Ground(g) => g.structured_jacobian(t, y, j),
            Scene::Hybrid(h, _) => h.structured_jacobian(t, y, j),
        }
    }

    fn mass_is_constant(&self) -> bool {
        match self {
            Scene::Ground(g) => g.mass_is_constant(),
            Scene::Hybrid(h, _) => h.mass_is_constant(),
        }
    }

    fn jacobian_pattern(&self) -> Option<JacobianPattern> {
        match self {
            Scene::Ground(g) => g.jacobian_pattern(),
            Scene::Hybrid(h, _) => h.jacobian_pattern(),
        }
    }
}
