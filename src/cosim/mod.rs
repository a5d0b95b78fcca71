//! The co-simulation runtime: a scene, its integrator and its inputs, stepped from one
//! communication point to the next. It knows the physics only through [`Scene`], and nothing of
//! the C ABI: the FMI layer ([`crate::fmi2`]) maps variables onto [`Settings`], [`Inputs`] and
//! [`Outputs`].
//!
//! The integrator keeps its history across communication points and lands exactly on each one
//! (a stop time, not a restart); it restarts at order 1 only where an input really jumps.

mod scene;
mod signals;

pub use scene::{GroundScene, Scene};
pub use signals::{Inputs, Signal};

use std::path::PathBuf;

use crate::ode::{Bdf, BdfOptions, BdfSnapshot, Tolerance};

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
        }
    }
}

/// Everything fixed at initialisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// 1 = engine on rigid ground.
    pub scene: i32,
    /// Engine configuration JSON; `None` = built-in defaults.
    pub config_file: Option<PathBuf>,
    pub effects: EffectSwitches,
    /// Smooth fade-in of the engine excitation, s (0 = instantly).
    pub fade_in_time: f64,
    /// Crank angle at the start time, rad.
    pub crank_start_angle: f64,
    pub rel_tol: f64,
    pub abs_tol: f64,
    pub max_order: i32,
    pub stability_limit_detection: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            scene: 1,
            config_file: None,
            effects: EffectSwitches::default(),
            fade_in_time: 0.1,
            crank_start_angle: 0.0,
            rel_tol: 1e-5,
            abs_tol: 1e-8,
            max_order: 5,
            stability_limit_detection: true,
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
    scene: GroundScene,
    integrator: Bdf,
    inputs: Inputs,
    options: BdfOptions,
}

impl Simulation {
    /// Builds the scene, finds its static equilibrium under the inputs at `t0` and starts the
    /// integrator there.
    pub fn new(settings: &Settings, t0: f64, inputs: &Inputs) -> Result<Simulation, String> {
        inputs.validate()?;
        if settings.scene != 1 {
            return Err(format!("scene {} is not available (1 = engine on rigid ground)", settings.scene));
        }
        let options = BdfOptions {
            rtol: settings.rel_tol,
            atol: Tolerance::Scalar(settings.abs_tol),
            max_order: usize::try_from(settings.max_order).unwrap_or(0),
            stability_limit_detection: settings.stability_limit_detection,
            ..BdfOptions::default()
        };
        let mut scene = GroundScene::new(settings)?;
        scene.set_inputs(inputs);
        let y0 = scene.initial_state(t0)?;
        let integrator = Bdf::new(&mut scene, t0, &y0, options.clone()).map_err(|e| e.to_string())?;
        Ok(Simulation { scene, integrator, inputs: *inputs, options })
    }

    /// Lines for the log describing the scene.
    pub fn describe(&self) -> Vec<String> {
        self.scene.describe()
    }

    pub fn time(&self) -> f64 {
        self.integrator.t()
    }

    /// Applies inputs valid from the current time on. Returns whether an input jumped, in which
    /// case the integrator restarted at order 1 (its history describes the old inputs).
    pub fn set_inputs(&mut self, inputs: &Inputs) -> Result<bool, String> {
        inputs.validate()?;
        let t = self.integrator.t();
        let jumped = !self.inputs.continue_into(inputs, t);
        self.inputs = *inputs;
        self.scene.set_inputs(inputs);
        if jumped {
            self.integrator.restart(&mut self.scene, None).map_err(|e| e.to_string())?;
        }
        Ok(jumped)
    }

    /// Integrates to exactly `t`, keeping the history for the next call.
    pub fn advance_to(&mut self, t: f64) -> Result<(), StepFailure> {
        self.integrator.advance_to(&mut self.scene, t).map_err(|e| StepFailure {
            message: e.to_string(),
            reached: self.integrator.t(),
        })
    }

    /// Outputs at the current time, with accelerations from one evaluation of the equations of
    /// motion.
    pub fn outputs(&mut self) -> Result<Outputs, String> {
        let t = self.integrator.t();
        let y = self.integrator.y().to_vec();
        self.scene.outputs(t, &y)
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

    /// What changes over time, as numbers: the inputs and the integrator state. The scene
    /// itself is rebuilt from the settings.
    pub fn dynamic_state(&self) -> Vec<f64> {
        let mut v = self.inputs.to_vec();
        v.extend(self.integrator.snapshot().to_vec());
        v
    }

    pub fn restore_dynamic_state(&mut self, data: &[f64]) -> Result<(), String> {
        if data.len() < Inputs::FLAT_LEN {
            return Err("simulation state is truncated".into());
        }
        let (inputs, integrator) = data.split_at(Inputs::FLAT_LEN);
        let inputs = Inputs::from_slice(inputs)?;
        let snapshot = BdfSnapshot::from_slice(integrator).map_err(|e| e.to_string())?;
        self.integrator.restore(&snapshot).map_err(|e| e.to_string())?;
        self.inputs = inputs;
        self.scene.set_inputs(&inputs);
        let _ = &self.options;
        Ok(())
    }
}
