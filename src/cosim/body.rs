//! The body FMU's runtime: the vehicle's reduced body alone
//! ([`crate::model::body_alone::BodyAlone`]), stepped from one communication point
//! to the next under the mount forces given as ramps. Its modal equations are propagated
//! exactly, so it has no integrator settings; it starts in static equilibrium under the forces
//! at the start time.

use super::scene::{vehicle_config_with_replacements, ComfortPoints};
use super::settings::Replaced;
use super::{
    Counters, Error, Input, Inputs, Outputs, RampInput, Settings, StepFailure, FMU_MOUNTS,
};
use crate::model::body_alone::BodyAlone;
use crate::model::scene::build_body_alone;
use crate::model::{Mode, ModeKind};

/// The body alone with its state, ready to step.
#[derive(Clone)]
pub struct BodySimulation {
    model: BodyAlone,
    pub(super) notes: Vec<String>,
    replaced: Vec<Replaced>,
    time: f64,
    /// Modal coordinates, then their rates.
    state: Vec<f64>,
    inputs: Inputs,
    /// Where the comfort outputs are among the body's output points.
    comfort: ComfortPoints,
    initial_time: f64,
    initial_inputs: Inputs,
    steps: u64,
}

/// What a [`BodySimulation`]'s settings do not determine (see
/// [`BodySimulation::dynamic_state`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BodyState {
    initial_time: f64,
    initial_inputs: Inputs,
    inputs: Inputs,
    time: f64,
    state: Vec<f64>,
    steps: u64,
}

/// Applies the forces of `inputs`, sized to the model's mounts (checked by the model; on error
/// nothing changes), and returns the inputs as applied.
fn apply(model: &mut BodyAlone, inputs: &Inputs) -> Result<Inputs, Error> {
    let sized = inputs.sized(model.mount_points().len());
    model.set_forces(&sized.body_force)?;
    Ok(sized)
}

/// Applies the forces of `inputs`, sized to the model's mounts, each of which passed its rule
/// where it was set ([`BodyAlone::check_input`]), and returns the inputs as applied.
fn apply_checked(model: &mut BodyAlone, inputs: &Inputs) -> Result<Inputs, Error> {
    let sized = inputs.sized(model.mount_points().len());
    model.set_checked_forces(&sized.body_force)?;
    Ok(sized)
}

impl BodySimulation {
    /// Reduces (or reads from the cache) the vehicle's body and puts it in static equilibrium
    /// under the forces of `inputs` at `t0`.
    pub fn new(settings: &Settings, t0: f64, inputs: &Inputs) -> Result<Self, Error> {
        let (vehicle, replaced) = vehicle_config_with_replacements(settings)?;
        if vehicle.mounts.len() > FMU_MOUNTS {
            return Err(Error::Model(format!(
                "the configuration has {} mounts; the FMU exposes {FMU_MOUNTS}",
                vehicle.mounts.len()
            )));
        }
        let (mut model, mut notes) = build_body_alone(&vehicle, &settings.chassis)?;
        let inputs = apply(&mut model, inputs)?;
        let comfort = ComfortPoints::resolve(model.output_points().iter().map(|p| p.name.as_str()));
        let state = model.static_equilibrium(t0);
        notes.push(format!(
            "the body alone: {} modes on its suspension, forces at {} mount points, propagated \
             exactly (ramp inputs); static equilibrium under the forces at t = {t0} s",
            model.modes(),
            model.mount_points().iter().flatten().count()
        ));
        Ok(Self {
            model,
            notes,
            replaced,
            time: t0,
            state,
            initial_inputs: inputs.clone(),
            inputs,
            comfort,
            initial_time: t0,
            steps: 0,
        })
    }

    /// The body model.
    pub fn model(&self) -> &BodyAlone {
        &self.model
    }

    /// Lines for the log describing the body.
    pub fn describe(&self) -> Vec<String> {
        self.notes.clone()
    }

    /// The configuration values the settings replaced.
    pub fn replaced(&self) -> &[Replaced] {
        &self.replaced
    }

    /// The communication time reached.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The inputs in force.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// Whether the body accepts the forces of `inputs`, changing nothing.
    pub fn check_inputs(&self, inputs: &Inputs) -> Result<(), Error> {
        let sized = inputs.sized(self.model.mount_points().len());
        Ok(self.model.check_forces(&sized.body_force)?)
    }

    /// The body's rule for one input, changing nothing; an input the body does not have passes.
    pub fn check_input(&self, input: Input, ramp: &RampInput) -> Result<(), Error> {
        Ok(self.model.check_input(input, ramp)?)
    }

    /// Applies the forces of `inputs` from the current time on. The exact propagation needs no
    /// restart, so nothing "jumps" for the integrator: returns `false`.
    pub fn set_inputs(&mut self, inputs: &Inputs) -> Result<bool, Error> {
        self.inputs = apply(&mut self.model, inputs)?;
        Ok(false)
    }

    /// [`Self::set_inputs`] for forces each of which passed its rule where it was set
    /// ([`Self::check_input`]): the rules do not run again.
    pub fn set_checked_inputs(&mut self, inputs: &Inputs) -> Result<bool, Error> {
        self.inputs = apply_checked(&mut self.model, inputs)?;
        Ok(false)
    }

    /// Propagates to `t`.
    pub fn advance_to(&mut self, t: f64) -> Result<(), StepFailure> {
        if t.partial_cmp(&self.time).is_none_or(|o| o.is_lt()) {
            return Err(StepFailure {
                error: Error::Model(format!("{t} is behind the current time {}", self.time)),
                reached: self.time,
            });
        }
        self.model.advance(self.time, t, &mut self.state);
        self.time = t;
        self.steps += 1;
        Ok(())
    }

    /// Outputs at the communication time under the inputs in force.
    pub fn outputs(&self) -> Outputs {
        Self::outputs_of(&self.model, self.comfort, self.time, &self.state)
    }

    fn outputs_of(model: &BodyAlone, comfort: ComfortPoints, t: f64, y: &[f64]) -> Outputs {
        let o = model.outputs(t, y);
        let mut out = Outputs::default();
        for (slot, m) in out.mount_point.iter_mut().zip(&o.mounts) {
            *slot = *m;
        }
        if let Some((_, p)) = comfort.steering_wheel.and_then(|k| o.points.get(k)) {
            out.steering_wheel_acceleration = p.acceleration;
        }
        if let Some((_, p)) = comfort.seat.and_then(|k| o.points.get(k)) {
            out.seat_acceleration = p.acceleration;
        }
        out
    }

    /// Outputs at the communication time with the forces of `interface` (the state held; each
    /// force checked where it was set): the accelerations respond at once to the forces.
    pub fn outputs_with(&self, interface: &Inputs) -> Result<Outputs, Error> {
        let mut model = self.model.clone();
        apply_checked(&mut model, &self.inputs.with_interface(interface))?;
        Ok(Self::outputs_of(
            &model,
            self.comfort,
            self.time,
            &self.state,
        ))
    }

    /// The outputs' response to the force increments in `seed.body_force` (values only), the
    /// state held: exact, the accelerations being linear in the forces.
    pub fn input_sensitivities(&self, seed: &Inputs) -> Outputs {
        let mut out = Outputs::default();
        let points = self.model.mount_points();
        let seed = seed.sized(points.len());
        let response = |p: usize| {
            let mut a = [0.0; 3];
            for (q, f) in points.iter().zip(&seed.body_force) {
                let Some(q) = q else { continue };
                let m = self.model.acceleration_per_force(p, *q);
                for (r, ar) in a.iter_mut().enumerate() {
                    *ar += (0..3).map(|c| m[r][c] * f[c].value).sum::<f64>();
                }
            }
            a
        };
        for (slot, p) in out.mount_point.iter_mut().zip(points) {
            if let Some(p) = p {
                slot.acceleration = response(*p);
            }
        }
        let body_point = |k: Option<usize>| k.map(|k| self.model.output_points()[k].point);
        if let Some(p) = body_point(self.comfort.steering_wheel) {
            out.steering_wheel_acceleration = response(p);
        }
        if let Some(p) = body_point(self.comfort.seat) {
            out.seat_acceleration = response(p);
        }
        out
    }

    /// The body's own modes, ascending: frequency and modal damping of each.
    pub fn natural_modes(&self) -> Vec<Mode> {
        let body = self.model.body();
        body.omega
            .iter()
            .zip(&body.zeta)
            .enumerate()
            .map(|(k, (w, z))| {
                let hz = w / (2.0 * std::f64::consts::PI);
                Mode {
                    frequency_hz: hz,
                    damping_ratio: *z,
                    kind: ModeKind::Body {
                        mode: k,
                        uncoupled_hz: hz,
                        point: String::new(),
                    },
                    description: format!("body mode {k} on its suspension"),
                    powertrain_fraction: 0.0,
                    powertrain_directions: [0.0; 6],
                    centre_of_mass_directions: [0.0; 6],
                    kinetic_fractions: Vec::new(),
                    mount_strain_fraction: 0.0,
                }
            })
            .collect()
    }

    /// Steps taken.
    pub fn counters(&self) -> Counters {
        Counters {
            steps: self.steps,
            ..Counters::default()
        }
    }

    /// Number of states (modal coordinates and rates).
    pub fn state_count(&self) -> usize {
        self.state.len()
    }

    /// Everything the settings do not determine.
    pub fn dynamic_state(&self) -> BodyState {
        BodyState {
            initial_time: self.initial_time,
            initial_inputs: self.initial_inputs.clone(),
            inputs: self.inputs.clone(),
            time: self.time,
            state: self.state.clone(),
            steps: self.steps,
        }
    }

    /// Rebuilds from the settings and a [`BodyState`].
    pub fn restore(settings: &Settings, saved: &BodyState) -> Result<Self, Error> {
        if !(saved.time.is_finite() && saved.initial_time.is_finite())
            || saved.state.iter().any(|x| !x.is_finite())
        {
            return Err(Error::Model(
                "body state holds a non-finite time or state".into(),
            ));
        }
        let mut sim = Self::new(settings, saved.initial_time, &saved.initial_inputs)?;
        if saved.state.len() != sim.state.len() {
            return Err(Error::Model(format!(
                "body state has {} states, this body {}",
                saved.state.len(),
                sim.state.len()
            )));
        }
        sim.set_inputs(&saved.inputs)?;
        sim.time = saved.time;
        sim.state.copy_from_slice(&saved.state);
        sim.steps = saved.steps;
        Ok(sim)
    }
}
