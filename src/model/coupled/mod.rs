//! The one coupled model: a powertrain on mounts in a body, as an [`OdeProblem`](crate::ode::OdeProblem).
//!
//! Components and what they contribute:
//! - the powertrain ([`Powertrain`]): 1 or 2 free rigid bodies with their composite-body dynamics,
//!   the crank angle relative to the monoblock, gas forces, ring carriers;
//! - the speed follower ([`SpeedFollower`]): the crank speed following the speed set-point;
//! - the body ([`ReducedChassis`]): modal coordinates `η̈_k + 2ζ_k ω_k η̇_k + ω_k² η_k = Σ_p φ_{p,k}·F_p`
//!   and named points; rigid ground is the body without modes;
//! - mounts ([`Mount`]): connectors between a housing bracket and a ground point or a body point;
//! - output points: named body points whose accelerations are reported.
//!
//! [`StateLayout`] alone knows where each component's coordinates live. The equations are
//! explicit, `y' = f(t, y)`: the powertrain's velocity rows are `M_b⁻¹ Q_b` (one 6×6 solve per
//! body), so the integrator needs no mass matrix. The Newton strategy follows from the structure
//! ([`jacobian`]): a dense matrix of the engine block when the body has no modes, block-diagonal
//! plus low rank through the mount forces otherwise.
//!
//! The body is linear about a reference state that already carries its own weight: only the
//! mount forces act on it, so at the static equilibrium it deflects by the powertrain's weight.
//!
//! Crank-drive semantics: the crank speed is the crankshaft's spin about its own axis in inertial
//! space (a flywheel held by the drivetrain); the crank angle relative to the monoblock is a state
//! with `φ' = ω_c − e_crank·ω_block`. That is what lets the mass and gas torques react on the block
//! (paper §4.2) and keeps free vibration with the crank at rest conservative.

pub mod decoupling;
mod energy;
mod evaluate;
pub mod interface;
pub mod jacobian;
mod layout;
pub mod linear;
pub mod modes;
mod nominal;
pub mod outputs;
pub mod snapshot;
mod statics;

pub use decoupling::{Axis, MountStiffness, RigidPowertrain};
pub use evaluate::Evaluation;
pub use layout::StateLayout;
pub use linear::Linearisation;
pub use modes::{mode_table, Direction, Mode, ModeKind};
pub use nominal::{describe_absolute_tolerance, FALLBACK_NOMINAL, RESOLVED_FRACTION};
pub use outputs::{BodyMotion, Outputs, PointMotion};
pub use snapshot::ModelSnapshot;
pub use statics::StaticsError;

use nalgebra::Vector3;

use super::effects::Effects;
use super::follower::SpeedFollower;
use super::inputs::{Input, InputError, ModelInputs, RampInput};
use super::mount::{Mount, MountConfig};
use super::powertrain::assembly::v3;
use super::powertrain::Powertrain;
use super::validate::ConfigError;
use crate::cms::ReducedChassis;

/// Largest distance (m) between a mount's bracket and the body node it is attached to.
pub const MOUNT_MATCH_TOLERANCE: f64 = 1e-3;

/// What a mount's far end is attached to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MountTarget {
    /// A fixed point (rigid ground).
    Ground,
    /// Point `p` of the body (its motion is `Σ_k φ_{p,k} η_k`).
    BodyPoint(usize),
    /// A point of a body outside the model, moving as the mount's
    /// [`AttachmentMotion`](super::inputs::AttachmentMotion) input says (scene 3).
    External,
}

/// A mount with what it connects.
#[derive(Debug, Clone, PartialEq)]
pub struct ConnectedMount {
    /// The mount: its bracket on the powertrain, curves, damping and preload.
    pub mount: Mount,
    /// What its far end is attached to.
    pub target: MountTarget,
}

/// A named body point whose motion is an output.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputPoint {
    /// The point's name in the vehicle configuration (`steering_wheel`, `seat_rail`, …).
    pub name: String,
    /// Index into the body's points.
    pub point: usize,
}

/// Why the coupled model could not be assembled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// The vehicle configuration is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The body is unusable: inconsistent or non-finite modal data, or a mount's body node or an
    /// output point it lacks.
    #[error("body: {0}")]
    Body(String),
}

/// The powertrain on its mounts in a body (or on rigid ground).
#[derive(Debug, Clone)]
pub struct CoupledModel {
    powertrain: Powertrain,
    follower: SpeedFollower,
    body: ReducedChassis,
    /// Per configured mount; `None` for a removed mount.
    mounts: Vec<Option<ConnectedMount>>,
    outputs: Vec<OutputPoint>,
    layout: StateLayout,
    inputs: ModelInputs,
    fade_start: f64,
    /// Hand the integrator a dense Jacobian even where the structure allows block plus low rank
    /// (comparisons).
    dense_newton: bool,
    /// Storage of the right-hand side's evaluation, reused between calls.
    scratch: Evaluation,
}

/// Checks the body's modal data before anything uses it.
fn check_body(body: &ReducedChassis) -> Result<(), ModelError> {
    let m = body.n_modes();
    if body.zeta.len() != m {
        return Err(ModelError::Body(format!(
            "{m} frequencies but {} damping ratios",
            body.zeta.len()
        )));
    }
    for (k, (&w, &z)) in body.omega.iter().zip(&body.zeta).enumerate() {
        if !(w.is_finite() && w >= 0.0) {
            return Err(ModelError::Body(format!(
                "body mode {k}: omega {w} rad/s must be finite and non-negative"
            )));
        }
        if !(z.is_finite() && z >= 0.0) {
            return Err(ModelError::Body(format!(
                "body mode {k}: damping ratio {z} must be finite and non-negative"
            )));
        }
    }
    for p in &body.points {
        if p.shape.len() != m {
            return Err(ModelError::Body(format!(
                "point '{}' has {} mode-shape rows for {m} modes",
                p.name,
                p.shape.len()
            )));
        }
        if p.shape.iter().flatten().any(|v| !v.is_finite()) {
            return Err(ModelError::Body(format!(
                "point '{}' has a non-finite mode-shape entry",
                p.name
            )));
        }
    }
    Ok(())
}

/// Index of the body point `name`; `what` names the reference in the error (which lists the
/// body's points).
pub(super) fn point_index(
    body: &ReducedChassis,
    name: &str,
    what: &str,
) -> Result<usize, ModelError> {
    body.points
        .iter()
        .position(|p| p.name == name)
        .ok_or_else(|| {
            ModelError::Body(format!(
                "{what} refers to body point '{name}', which the body does not have (points: {})",
                body.points
                    .iter()
                    .map(|p| p.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
}

/// The body points of the named `outputs`, in their order.
pub(super) fn output_points(
    body: &ReducedChassis,
    outputs: &[String],
) -> Result<Vec<OutputPoint>, ModelError> {
    outputs
        .iter()
        .map(|name| {
            Ok(OutputPoint {
                name: name.clone(),
                point: point_index(body, name, "an output")?,
            })
        })
        .collect()
}

impl CoupledModel {
    /// Assembles the model. With a body without modes (rigid ground) every mount attaches at its
    /// ground point; otherwise at its `body_node`, which the body must provide, as must every
    /// name in `outputs`.
    pub fn new(
        powertrain: Powertrain,
        mounts: &[MountConfig],
        body: ReducedChassis,
        outputs: &[String],
        follower: SpeedFollower,
    ) -> Result<Self, ModelError> {
        Self::assemble(powertrain, mounts, body, outputs, follower, false)
    }

    /// [`Self::new`], or with `external` every mount attached at its ground point to a body
    /// outside the model whose motion is an input (the body must then have no modes).
    ///
    /// Long on purpose: it checks and wires every mount against the body once; split, the
    /// partly built model would travel between the pieces.
    fn assemble(
        powertrain: Powertrain,
        mounts: &[MountConfig],
        body: ReducedChassis,
        outputs: &[String],
        follower: SpeedFollower,
        external: bool,
    ) -> Result<Self, ModelError> {
        check_body(&body)?;
        follower.validate("speed_follower")?;
        let ground = body.n_modes() == 0;
        if external && !ground {
            return Err(ModelError::Body(
                "a model whose mounts sit on an external body cannot have body modes of its own"
                    .into(),
            ));
        }
        let mut connected = Vec::with_capacity(mounts.len());
        for (i, m) in mounts.iter().enumerate() {
            m.validate(&format!("mounts[{i}]"))?;
            if !m.active {
                connected.push(None);
                continue;
            }
            let (attachment, target) = if ground {
                let at = m.ground_point.as_ref().unwrap_or(&m.bracket);
                let target = if external {
                    MountTarget::External
                } else {
                    MountTarget::Ground
                };
                (v3(at), target)
            } else {
                let node = m.body_node.as_deref().ok_or_else(|| {
                    ModelError::Config(ConfigError {
                        field: format!("mounts[{i}].body_node"),
                        message: format!(
                            "mount '{}' names no body node, but the vehicle has an elastic body",
                            m.name
                        ),
                    })
                })?;
                let p = point_index(&body, node, &format!("mount '{}'", m.name))?;
                let at = v3(&body.points[p].position);
                // The mounts pass forces only: bracket and node must coincide, or the force pair
                // would leave a moment unbalanced.
                let gap = (at - v3(&m.bracket)).norm();
                if gap > MOUNT_MATCH_TOLERANCE {
                    return Err(ModelError::Body(format!(
                        "mount {} ('{}') has its bracket at ({:.4}, {:.4}, {:.4}) m; its body node '{node}' is {:.1} mm away (limit {:.1} mm)",
                        i + 1,
                        m.name,
                        m.bracket[0],
                        m.bracket[1],
                        m.bracket[2],
                        gap * 1e3,
                        MOUNT_MATCH_TOLERANCE * 1e3
                    )));
                }
                (at, MountTarget::BodyPoint(p))
            };
            connected.push(Some(ConnectedMount {
                mount: Mount::from_config(m, attachment),
                target,
            }));
        }
        let active = connected.iter().flatten().count();
        if active < 3 {
            return Err(ConfigError {
                field: "mounts".into(),
                message: format!(
                    "{active} active mounts cannot carry the powertrain statically; need at least 3"
                ),
            }
            .into());
        }
        let outputs = output_points(&body, outputs)?;
        let layout = StateLayout::new(
            powertrain.body_count(),
            follower.is_dynamic(),
            body.n_modes(),
        );
        Ok(Self {
            inputs: ModelInputs::new(mounts.len()),
            powertrain,
            follower,
            body,
            mounts: connected,
            outputs,
            layout,
            fade_start: 0.0,
            dense_newton: false,
            scratch: Evaluation::empty(),
        })
    }

    /// The powertrain of `config` on its mounts on rigid ground (scene 1).
    pub fn on_ground(config: &super::VehicleConfig) -> Result<Self, ModelError> {
        Self::with_body(config, ReducedChassis::rigid_ground())
    }

    /// The powertrain of `config` on its mounts on a body outside the model (scene 3): each
    /// mount's far end sits at its ground point displaced by its
    /// [`AttachmentMotion`](super::inputs::AttachmentMotion) input. With every attachment at
    /// rest this is [`Self::on_ground`].
    pub fn on_external_body(config: &super::VehicleConfig) -> Result<Self, ModelError> {
        config.validate()?;
        let powertrain = Powertrain::new(config.engine.clone(), config.effects, config.gravity)?;
        Self::assemble(
            powertrain,
            &config.mounts,
            ReducedChassis::rigid_ground(),
            &[],
            config.speed_follower,
            true,
        )
    }

    /// The vehicle of `config` with the given (reduced) body; a body without modes is rigid
    /// ground.
    pub fn with_body(
        config: &super::VehicleConfig,
        body: ReducedChassis,
    ) -> Result<Self, ModelError> {
        config.validate()?;
        let powertrain = Powertrain::new(config.engine.clone(), config.effects, config.gravity)?;
        let outputs: Vec<String> = if body.n_modes() == 0 {
            Vec::new()
        } else {
            config.outputs.clone()
        };
        Self::new(
            powertrain,
            &config.mounts,
            body,
            &outputs,
            config.speed_follower,
        )
    }

    /// Makes the integrator use a dense `n × n` Newton matrix (`true`) instead of the
    /// block-diagonal plus low-rank one: the two must give the same solution; the dense one costs
    /// `O(n³)` per factorisation.
    pub fn set_dense_newton(&mut self, dense: bool) {
        self.dense_newton = dense;
    }

    /// The powertrain component (engine bodies, crank drive, ring carriers).
    pub fn powertrain(&self) -> &Powertrain {
        &self.powertrain
    }

    /// The effect switches in force.
    pub fn effects(&self) -> &Effects {
        self.powertrain.effects()
    }

    /// The reduced body (no modes and no points on rigid ground).
    pub fn body(&self) -> &ReducedChassis {
        &self.body
    }

    /// Where each component's coordinates sit in the state vector.
    pub fn layout(&self) -> &StateLayout {
        &self.layout
    }

    /// How the crank follows the speed set-point.
    pub fn follower(&self) -> &SpeedFollower {
        &self.follower
    }

    /// Mounts by configuration index (`None`: removed).
    pub fn mounts(&self) -> &[Option<ConnectedMount>] {
        &self.mounts
    }

    /// The connected mounts attached to body points: (configuration index, mount, body point).
    pub fn body_mounts(&self) -> impl Iterator<Item = (usize, &Mount, usize)> + '_ {
        self.mounts.iter().enumerate().filter_map(|(i, m)| {
            let m = m.as_ref()?;
            match m.target {
                MountTarget::BodyPoint(p) => Some((i, &m.mount, p)),
                MountTarget::Ground | MountTarget::External => None,
            }
        })
    }

    /// The body points whose motion is reported, in output order.
    pub fn output_points(&self) -> &[OutputPoint] {
        &self.outputs
    }

    /// The inputs in force (speed set-point, load torque, mount scales).
    pub fn inputs(&self) -> &ModelInputs {
        &self.inputs
    }

    /// Number of body modes.
    pub fn modes_count(&self) -> usize {
        self.body.n_modes()
    }

    /// Weight of the powertrain (N).
    pub fn powertrain_weight(&self) -> f64 {
        self.powertrain.mass() * -self.powertrain.gravity().z
    }

    /// Crank speed set-point `ω(t) = value + rate (t − since)` (rad/s).
    pub fn set_crank_speed(&mut self, since: f64, value: f64, rate: f64) -> Result<(), InputError> {
        let r = RampInput { value, rate, since };
        if !(value.is_finite() && rate.is_finite() && since.is_finite()) {
            return Err(InputError::Other(format!(
                "crank speed {value} rad/s, rate {rate} rad/s² must be finite"
            )));
        }
        self.inputs.crank_speed = r;
        Ok(())
    }

    /// Load torque on the housing about +y (N m) and its time derivative.
    pub fn set_load_torque(&mut self, since: f64, value: f64, rate: f64) -> Result<(), InputError> {
        if !(value.is_finite() && rate.is_finite() && since.is_finite()) {
            return Err(InputError::Other(format!(
                "load torque {value} N m, rate {rate} N m/s must be finite"
            )));
        }
        self.inputs.load_torque = RampInput { value, rate, since };
        Ok(())
    }

    /// Constant stiffness and damping scale factors of mount `index` (configuration order).
    pub fn set_mount_scales(
        &mut self,
        index: usize,
        stiffness: f64,
        damping: f64,
    ) -> Result<(), InputError> {
        self.set_mount_scale_ramps(
            index,
            RampInput::constant(stiffness),
            RampInput::constant(damping),
        )
    }

    /// Stiffness and damping scale ramps of mount `index` (configuration order); values >= 0.
    pub fn set_mount_scale_ramps(
        &mut self,
        index: usize,
        stiffness: RampInput,
        damping: RampInput,
    ) -> Result<(), InputError> {
        let n = self.mounts.len();
        if index >= n {
            return Err(InputError::Other(format!(
                "mount {} does not exist (the model has {n} mounts)",
                index + 1
            )));
        }
        let mut trial = self.inputs.clone();
        trial.stiffness_scale[index] = stiffness;
        trial.damping_scale[index] = damping;
        trial.validate(n)?;
        self.inputs = trial;
        Ok(())
    }

    /// All inputs at once (validated as a whole; on error nothing changes).
    pub fn set_inputs(&mut self, inputs: &ModelInputs) -> Result<(), InputError> {
        inputs.validate(self.mounts.len())?;
        self.inputs = inputs.clone();
        Ok(())
    }

    /// The model's rule for one input ([`Input::check`]); an input this model does not have (a
    /// mount beyond its configuration, a force on the body alone) is none of its business.
    pub fn check_input(&self, input: Input, ramp: &RampInput) -> Result<(), InputError> {
        let mount = match input {
            Input::BodyForce(..) => return Ok(()),
            Input::CrankSpeed | Input::LoadTorque => None,
            Input::StiffnessScale(i)
            | Input::DampingScale(i)
            | Input::BodyDisplacement(i, _)
            | Input::BodyVelocity(i, _) => Some(i),
        };
        if mount.is_some_and(|i| i >= self.mounts.len()) {
            return Ok(());
        }
        input.check(ramp, f64::INFINITY)
    }

    /// All inputs at once, each of which passed its rule where it was set
    /// ([`Self::check_input`]): only their number per mount is checked, the rules do not run
    /// again.
    pub fn set_checked_inputs(&mut self, inputs: &ModelInputs) -> Result<(), InputError> {
        inputs.check_lengths(self.mounts.len())?;
        self.inputs = inputs.clone();
        Ok(())
    }

    /// Engine load between idle (0) and full load (1) of the Wiebe gas model, at run time.
    pub fn set_gas_load(&mut self, load: f64) -> Result<(), InputError> {
        self.powertrain.set_gas_load(load)
    }

    /// Start of the excitation fade-in.
    pub fn fade_start(&self) -> f64 {
        self.fade_start
    }

    /// Time from which the excitation fades in (set by [`Self::static_equilibrium`]).
    pub fn set_fade_start(&mut self, t: f64) -> Result<(), InputError> {
        if !t.is_finite() {
            return Err(InputError::Other(format!(
                "excitation fade-in start {t} s must be finite"
            )));
        }
        self.fade_start = t;
        Ok(())
    }

    /// Excitation scale at `t` (C² ramp over the configured fade-in time).
    pub fn excitation(&self, t: f64) -> f64 {
        let tf = self.powertrain.config().excitation_fade_in;
        if tf <= 0.0 {
            1.0
        } else {
            crate::model::blend::smooth_step((t - self.fade_start) / tf)
        }
    }

    /// Displacement and velocity of the far end of mount `i` (target `target`) at `(t, y)`.
    pub(crate) fn attachment_motion(
        &self,
        i: usize,
        target: MountTarget,
        t: f64,
        y: &[f64],
    ) -> (Vector3<f64>, Vector3<f64>) {
        match target {
            MountTarget::Ground => (Vector3::zeros(), Vector3::zeros()),
            MountTarget::BodyPoint(p) => (
                self.point_translation(p, &y[self.layout.eta()]),
                self.point_translation(p, &y[self.layout.eta_rate()]),
            ),
            MountTarget::External => {
                let (u, v) = self.inputs.body_motion[i].at(t);
                (Vector3::from(u), Vector3::from(v))
            }
        }
    }

    /// Whether the mounts sit on a body outside the model (scene 3).
    pub fn has_external_body(&self) -> bool {
        self.mounts
            .iter()
            .flatten()
            .any(|m| m.target == MountTarget::External)
    }

    /// Translation (or, for modal rates, velocity) of body point `p` for modal vector `x`.
    pub fn point_translation(&self, p: usize, x: &[f64]) -> Vector3<f64> {
        let mut u = Vector3::zeros();
        for (s, &e) in self.body.points[p].shape.iter().zip(x) {
            u += Vector3::new(s[0], s[1], s[2]) * e;
        }
        u
    }

    /// State with every powertrain body at its reference pose, the crank at the start angle, the
    /// follower at the current set-point and the body undeformed.
    pub fn reference_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.layout.dim()];
        y[self.layout.crank_angle()] = self.powertrain.start_angle();
        if let Some((w, a)) = self.layout.follower_states() {
            y[w] = self.inputs.crank_speed.at(self.fade_start);
            y[a] = self.inputs.crank_speed.rate;
        }
        y
    }

    /// Per state, the largest magnitude the integrator's relative tolerance applies to: one
    /// revolution for the cumulative crank angle (its phase is what must stay accurate), no cap
    /// elsewhere.
    pub fn magnitude_caps(&self) -> Vec<f64> {
        let mut caps = vec![f64::INFINITY; self.layout.dim()];
        caps[self.layout.crank_angle()] = 2.0 * std::f64::consts::PI;
        caps
    }

    /// Checks that `y` is a state of this model.
    pub fn check_state(&self, y: &[f64]) -> Result<(), crate::ode::ProblemError> {
        let n = self.layout.dim();
        if y.len() != n {
            return Err(crate::ode::ProblemError::Fatal(format!(
                "state has {} entries, the model has {n}",
                y.len()
            )));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(crate::ode::ProblemError::Fatal(format!(
                "state entry {i} is {}",
                y[i]
            )));
        }
        Ok(())
    }

    /// One line describing the assembled model, for logs.
    pub fn describe(&self) -> String {
        let active = self.mounts.iter().flatten().count();
        let follower = if self.follower.is_dynamic() {
            format!(
                "crank speed follows the set-point with τ = {} s",
                self.follower.time_constant
            )
        } else {
            "crank speed = set-point".to_owned()
        };
        format!(
            "{} powertrain bodies, {active} of {} mounts active, {} body modes, {} output points, {} states; {follower}; effects {:?}",
            self.powertrain.body_count(),
            self.mounts.len(),
            self.modes_count(),
            self.outputs.len(),
            self.layout.dim(),
            self.effects()
        )
    }
}
