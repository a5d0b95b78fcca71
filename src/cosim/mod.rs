//! The co-simulation runtime: a scene, its integrator and its inputs, stepped from one
//! communication point to the next. It knows the physics only through [`Scene`], and nothing of
//! the C ABI: the FMI layer ([`crate::fmi2`]) maps variables onto [`Settings`], [`Inputs`] and
//! [`Outputs`].
//!
//! The integrator keeps its history across communication points and lands exactly on each one
//! (a stop time, not a restart); it restarts at order 1 only where an input really jumps.

mod scene;
mod signals;

pub use crate::cms::CacheSetting;
pub use scene::{Scene, FMU_MOUNTS};
pub use signals::{Inputs, Signal};

use std::path::PathBuf;

use crate::ode::{Bdf, BdfOptions, BdfSnapshot, OdeProblem, Tolerance};

/// Name of the default configuration in the FMU's resources folder.
pub const DEFAULT_CONFIG_NAME: &str = "engine.json";

/// rpm → rad/s.
pub const RPM_TO_RAD_PER_S: f64 = std::f64::consts::PI / 30.0;

/// Which physical effects a scene includes (a switched-off effect costs nothing).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EffectSwitches {
    pub gas_forces: bool,
    pub mass_forces: bool,
    pub balance_shaft: bool,
    pub gyroscopic: bool,
    pub ring_carrier: bool,
    pub mount_nonlinearity: bool,
    /// Scene 2: elastic chassis; off: only its rigid-body modes on the suspension.
    pub chassis_flexibility: bool,
}

impl Default for EffectSwitches {
    fn default() -> Self {
        EffectSwitches {
            gas_forces: true,
            mass_forces: true,
            balance_shaft: true,
            gyroscopic: true,
            ring_carrier: true,
            mount_nonlinearity: true,
            chassis_flexibility: true,
        }
    }
}

/// The elastic chassis of scene 2.
#[derive(Debug, Clone, PartialEq)]
pub struct ChassisSettings {
    /// Keep the fixed-interface chassis modes below this frequency, Hz; 0 = automatic, from the
    /// highest excitation frequency the scene needs (see [`ChassisSettings::cutoff_hz`]).
    pub mode_cutoff_hz: f64,
    /// Interface DOFs of the mount nodes: translations (the mounts transmit forces only) or all
    /// six (adds the rotational constraint modes, up to several kHz, as a stiffness test).
    pub interface_rotations: bool,
    /// Factor on every chassis modal damping ratio (1 = the ADAMS table; 0 = undamped).
    pub modal_damping_scale: f64,
    /// Highest engine speed (rpm) and engine order the automatic cut-off must cover.
    pub max_rpm: f64,
    pub max_engine_order: f64,
    /// If positive: keep exactly this many fixed-interface modes instead (the cut-off is unused).
    pub max_modes: i32,
    /// Transverse stiffening bar between the front girders (paper §7.1).
    pub stiffening_bar: bool,
    /// Where the reduced chassis is cached.
    pub cache: CacheSetting,
}

/// Margin of the automatic cut-off over the highest excitation frequency: the mode nearest to it
/// must respond dynamically, not only quasi-statically.
pub const AUTO_CUTOFF_MARGIN: f64 = 1.2;

impl ChassisSettings {
    /// The cut-off in use: the explicit one, or max rpm × max order × margin.
    pub fn cutoff_hz(&self) -> f64 {
        if self.mode_cutoff_hz > 0.0 {
            self.mode_cutoff_hz
        } else {
            self.max_rpm / 60.0 * self.max_engine_order * AUTO_CUTOFF_MARGIN
        }
    }
}

impl Default for ChassisSettings {
    fn default() -> Self {
        ChassisSettings {
            mode_cutoff_hz: 0.0,
            modal_damping_scale: 1.0,
            interface_rotations: false,
            max_rpm: 2500.0,
            max_engine_order: 4.5,
            max_modes: 0,
            stiffening_bar: false,
            cache: CacheSetting::Default,
        }
    }
}

/// Everything fixed at initialisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// 1 = engine on rigid ground, 2 = engine in the elastic chassis.
    pub scene: i32,
    /// Engine configuration JSON; `None` = built-in defaults.
    pub config_file: Option<PathBuf>,
    pub effects: EffectSwitches,
    /// Combustion load, 0 = idle … 1 = full load (blends the Wiebe pressure curves).
    pub gas_load: f64,
    /// Smooth fade-in of the engine excitation, s (0 = instantly).
    pub fade_in_time: f64,
    /// Crank angle at the start time, rad.
    pub crank_start_angle: f64,
    pub rel_tol: f64,
    pub abs_tol: f64,
    pub max_order: i32,
    pub stability_limit_detection: bool,
    /// Used by scene 2 only.
    pub chassis: ChassisSettings,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            scene: 1,
            config_file: None,
            effects: EffectSwitches::default(),
            gas_load: 0.0,
            fade_in_time: 0.1,
            crank_start_angle: 0.0,
            rel_tol: 1e-5,
            abs_tol: 1e-8,
            max_order: 5,
            stability_limit_detection: true,
            chassis: ChassisSettings::default(),
        }
    }
}

/// Results at a communication point, SI units, vehicle frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Outputs {
    /// Force of each mount on the ground/chassis side (zero for a removed mount), N.
    pub mount_force: [[f64; 3]; 4],
    /// Cumulative crank angle, rad.
    pub crank_angle: f64,
    /// Powertrain (housing) CG displacement from its design position, m.
    pub powertrain_displacement: [f64; 3],
    /// Powertrain (housing) rotation vector, rad.
    pub powertrain_rotation: [f64; 3],
    /// Powertrain (housing) CG acceleration from the equations of motion, m/s².
    pub powertrain_acceleration: [f64; 3],
    /// Steering-wheel acceleration from the equations of motion, m/s² (scene 2; zero in scene 1).
    pub steering_wheel_acceleration: [f64; 3],
    /// Seat-rail acceleration from the equations of motion, m/s² (scene 2; zero in scene 1).
    pub seat_acceleration: [f64; 3],
}

/// Work counters of the integrator since initialisation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Counters {
    pub steps: u64,
    pub rhs_evaluations: u64,
    pub jacobian_evaluations: u64,
    pub factorizations: u64,
}

/// A step that could not be completed; the simulation stays at `reached`.
#[derive(Debug, Clone, PartialEq)]
pub struct StepFailure {
    pub message: String,
    pub reached: f64,
}

/// A scene with its integrator, ready to step.
#[derive(Clone)]
pub struct Simulation {
    scene: Scene,
    integrator: Bdf,
    /// Communication time and the state there. The integrator steps past communication points
    /// and interpolates, so its own time is usually a little ahead.
    time: f64,
    state: Vec<f64>,
    inputs: Inputs,
    /// Where and under which inputs the static equilibrium was found: with the settings, this
    /// rebuilds the scene exactly (fade-in start, mount operating points).
    initial_time: f64,
    initial_inputs: Inputs,
}

impl Simulation {
    /// Builds the scene, finds its static equilibrium under the inputs at `t0` and starts the
    /// integrator there.
    pub fn new(settings: &Settings, t0: f64, inputs: &Inputs) -> Result<Simulation, String> {
        inputs.validate()?;
        let mut options = BdfOptions {
            rtol: settings.rel_tol,
            atol: Tolerance::Scalar(settings.abs_tol),
            max_order: usize::try_from(settings.max_order).unwrap_or(0),
            stability_limit_detection: settings.stability_limit_detection,
            ..BdfOptions::default()
        };
        let mut scene = Scene::build(settings)?;
        scene.set_inputs(inputs)?;
        options.magnitude_cap = Some(scene.magnitude_caps());
        let y0 = scene.initial_state(t0)?;
        let integrator = Bdf::new(&mut scene, t0, &y0, options).map_err(|e| e.to_string())?;
        Ok(Simulation {
            scene,
            integrator,
            time: t0,
            state: y0,
            inputs: *inputs,
            initial_time: t0,
            initial_inputs: *inputs,
        })
    }

    /// Lines for the log describing the scene.
    pub fn describe(&self) -> Vec<String> {
        self.scene.describe()
    }

    /// Number of integrator states (what a switched-off effect saves).
    pub fn state_count(&self) -> usize {
        self.scene.dim()
    }

    /// The communication time reached.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Applies inputs valid from the current time on. Returns whether an input jumped, in which
    /// case the integrator restarted at order 1 from the state at the communication time (its
    /// history, and any step it took past that time, describe the old inputs).
    pub fn set_inputs(&mut self, inputs: &Inputs) -> Result<bool, String> {
        inputs.validate()?;
        let t = self.time;
        let jumped = !self.inputs.continue_into(inputs, t);
        let previous = self.inputs;
        self.scene.set_inputs(inputs)?;
        self.inputs = *inputs;
        if jumped {
            if let Err(e) = self.integrator.restart_at(&mut self.scene, t, &self.state) {
                // Leave everything as it was: the old inputs still describe the integrator.
                self.scene.set_inputs(&previous)?;
                self.inputs = previous;
                return Err(e.to_string());
            }
        }
        Ok(jumped)
    }

    /// Integrates to `t`, keeping the history for the next call. The integrator takes the
    /// steps its error control wants, past `t` if need be, and the state at `t` is
    /// interpolated: communication points cost no extra steps.
    pub fn advance_to(&mut self, t: f64) -> Result<(), StepFailure> {
        if t < self.time {
            return Err(StepFailure {
                message: format!("{t} is behind the current time {}", self.time),
                reached: self.time,
            });
        }
        self.integrator
            .advance_past(&mut self.scene, t, &mut self.state)
            .map_err(|e| StepFailure {
                message: e.to_string(),
                reached: self.integrator.t().min(t),
            })?;
        self.time = t;
        Ok(())
    }

    /// Outputs at the communication time, with accelerations from one evaluation of the
    /// equations of motion.
    pub fn outputs(&mut self) -> Result<Outputs, String> {
        self.scene.outputs(self.time, &self.state)
    }

    pub fn counters(&self) -> Counters {
        let s = self.integrator.stats();
        Counters {
            steps: s.steps,
            rhs_evaluations: s.rhs_evals,
            jacobian_evaluations: s.jac_evals,
            factorizations: s.factorizations,
        }
    }

    /// Everything that is not in the settings, as numbers: where the simulation started, the
    /// inputs, and the integrator state. [`Simulation::restore`] rebuilds from it.
    pub fn dynamic_state(&self) -> Vec<f64> {
        let mut v = vec![self.initial_time];
        v.extend(self.initial_inputs.to_vec());
        v.extend(self.inputs.to_vec());
        v.push(self.time);
        v.extend(&self.state);
        v.extend(self.integrator.snapshot().to_f64_vec());
        v
    }

    /// Rebuilds a simulation from its settings and [`Simulation::dynamic_state`]; continuing it
    /// reproduces the original run bit for bit.
    pub fn restore(settings: &Settings, data: &[f64]) -> Result<Simulation, String> {
        let n = Inputs::FLAT_LEN;
        if data.len() < 2 + 2 * n {
            return Err("simulation state is truncated".into());
        }
        let initial_time = data[0];
        let initial_inputs = Inputs::from_slice(&data[1..1 + n])?;
        let inputs = Inputs::from_slice(&data[1 + n..1 + 2 * n])?;
        let time = data[1 + 2 * n];
        let mut sim = Simulation::new(settings, initial_time, &initial_inputs)?;
        let states = sim.state.len();
        let start = 2 + 2 * n;
        let state = data
            .get(start..start + states)
            .ok_or("simulation state is truncated")?;
        if !time.is_finite() || state.iter().any(|v| !v.is_finite()) {
            return Err("simulation state holds a non-finite time or state".into());
        }
        let snapshot =
            BdfSnapshot::from_f64_slice(&data[start + states..]).map_err(|e| e.to_string())?;
        sim.integrator
            .restore(&snapshot)
            .map_err(|e| e.to_string())?;
        sim.scene.set_inputs(&inputs)?;
        sim.inputs = inputs;
        sim.time = time;
        sim.state.copy_from_slice(state);
        Ok(sim)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restored_dynamic_state_continues_bit_for_bit() {
        let settings = Settings::default();
        let mut a = Simulation::new(&settings, 0.0, &Inputs::steady(1200.0)).unwrap();
        for k in 1..=20 {
            a.advance_to(k as f64 * 1e-3).unwrap();
        }
        let saved = a.dynamic_state();
        let mut b = Simulation::restore(&settings, &saved).unwrap();
        assert_eq!(b.dynamic_state(), saved);
        for k in 21..=40 {
            let t = k as f64 * 1e-3;
            a.advance_to(t).unwrap();
            b.advance_to(t).unwrap();
            assert_eq!(a.outputs().unwrap(), b.outputs().unwrap(), "t = {t}");
        }
    }
}
