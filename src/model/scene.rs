//! Scenes as configurations of components: the vehicle's powertrain and mounts on rigid ground
//! (scene 1, paper Table 1 left column), or in the vehicle's elastic body reduced to the modes the
//! scene needs (scene 2, Table 1 middle column).

use crate::cms::{
    reduce_cached_with_notes, BodyDamping, BodySource, BulkDeckBody, CacheOutcome, CacheSetting,
    DmigBodySource, InterfaceDofs, ModeSelection, ReducedChassis, ReductionSpec,
};

use super::body_alone::BodyAlone;
use super::coupled::CoupledModel;
use super::vehicle::{BodyConfig, VehicleConfig};

/// With chassis flexibility off, the body modes kept: the rigid-body modes on the suspension
/// (1–5 Hz; the first elastic mode of the default body is above 20 Hz).
pub const RIGID_BODY_HZ: f64 = 10.0;

/// Margin of the automatic cut-off over the highest excitation frequency: the mode nearest to it
/// must respond dynamically, not only quasi-statically.
pub const AUTO_CUTOFF_MARGIN: f64 = 1.2;

/// Which structure the scene has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneKind {
    /// Powertrain on its mounts on rigid ground.
    Ground,
    /// Powertrain on its mounts in the vehicle's elastic body.
    Body,
    /// Powertrain on its mounts on a body outside the model, whose motion at each mount is an
    /// input (a vehicle co-simulation carries the body).
    ExternalBody,
}

impl SceneKind {
    /// The scene by its number (1: rigid ground, 2: elastic body, as in the paper's Table 1;
    /// 3: external body).
    pub fn from_number(number: i32) -> Result<SceneKind, String> {
        match number {
            1 => Ok(SceneKind::Ground),
            2 => Ok(SceneKind::Body),
            3 => Ok(SceneKind::ExternalBody),
            other => Err(format!(
                "scene {other} does not exist (1: engine on rigid ground, 2: engine in the elastic chassis, 3: engine on an external body)"
            )),
        }
    }

    /// The scene's number.
    pub fn number(self) -> i32 {
        match self {
            SceneKind::Ground => 1,
            SceneKind::Body => 2,
            SceneKind::ExternalBody => 3,
        }
    }

    /// What the scene is, for logs.
    pub fn describe(self) -> &'static str {
        match self {
            SceneKind::Ground => "engine on rigid ground",
            SceneKind::Body => "engine in the elastic chassis",
            SceneKind::ExternalBody => "engine on an external body",
        }
    }
}

/// What the scene needs of the body: mode selection, interface, damping, cache.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyOptions {
    /// Keep the fixed-interface modes below this frequency, Hz; 0 = automatic, from
    /// `max_rpm / 60 × max_engine_order × AUTO_CUTOFF_MARGIN`.
    pub mode_cutoff_hz: f64,
    /// If positive: keep exactly this many fixed-interface modes instead.
    pub max_modes: usize,
    /// Highest engine speed the scene must represent, rpm; with `max_engine_order` it sets the
    /// automatic mode cut-off.
    pub max_rpm: f64,
    /// Highest engine order of interest (excitation frequencies are order × rpm / 60).
    pub max_engine_order: f64,
    /// All six DOFs of the mount nodes as interface (rotational constraint modes, kHz), instead
    /// of the translations (the mounts transmit forces only).
    pub interface_rotations: bool,
    /// Factor on the body's physical modal damping, its table and per-mode overrides (1 = as
    /// configured; 0 = undamped); the numerical damping of the interface modes stays.
    pub modal_damping_scale: f64,
    /// Procedural body only: the transverse stiffening bar between the front girders.
    pub stiffening_bar: bool,
    /// Procedural body only: the stiffer front plate under the steering column.
    pub stiff_front_plate: bool,
    /// Where the reduced body is cached, or no cache.
    pub cache: CacheSetting,
}

impl Default for BodyOptions {
    /// The paper's question: engine orders up to 4.5 at up to 2500 rpm (an automatic cut-off of
    /// 225 Hz), translational interface, the body's damping as configured, the body as designed,
    /// cached.
    fn default() -> Self {
        BodyOptions {
            mode_cutoff_hz: 0.0,
            max_modes: 0,
            max_rpm: 2500.0,
            max_engine_order: 4.5,
            interface_rotations: false,
            modal_damping_scale: 1.0,
            stiffening_bar: false,
            stiff_front_plate: false,
            cache: CacheSetting::Default,
        }
    }
}

/// One of the [`BodyOptions`], to name it in an error without its value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyOption {
    /// [`BodyOptions::mode_cutoff_hz`].
    ModeCutoff,
    /// [`BodyOptions::max_modes`].
    MaxModes,
    /// [`BodyOptions::max_rpm`].
    MaxRpm,
    /// [`BodyOptions::max_engine_order`].
    MaxEngineOrder,
    /// [`BodyOptions::interface_rotations`].
    InterfaceRotations,
    /// [`BodyOptions::modal_damping_scale`].
    ModalDampingScale,
    /// [`BodyOptions::stiffening_bar`].
    StiffeningBar,
    /// [`BodyOptions::stiff_front_plate`].
    StiffFrontPlate,
    /// [`BodyOptions::cache`].
    Cache,
}

impl std::fmt::Display for BodyOption {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let field = match self {
            BodyOption::ModeCutoff => "mode_cutoff_hz",
            BodyOption::MaxModes => "max_modes",
            BodyOption::MaxRpm => "max_rpm",
            BodyOption::MaxEngineOrder => "max_engine_order",
            BodyOption::InterfaceRotations => "interface_rotations",
            BodyOption::ModalDampingScale => "modal_damping_scale",
            BodyOption::StiffeningBar => "stiffening_bar",
            BodyOption::StiffFrontPlate => "stiff_front_plate",
            BodyOption::Cache => "cache",
        };
        write!(f, "body option {field}")
    }
}

/// Why a scene could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// A body option is outside its domain or does not apply to this vehicle's body.
    #[error("{option} = {value} {rule}")]
    Option {
        /// The option at fault.
        option: BodyOption,
        /// Its value as given.
        value: String,
        /// The rule it breaks, as a sentence ending (e.g. "must be >= 0 and finite").
        rule: String,
    },
    /// The vehicle, its body or its reduction (in the configuration's terms).
    #[error("{0}")]
    Model(String),
}

impl From<String> for SceneError {
    fn from(message: String) -> Self {
        SceneError::Model(message)
    }
}

fn option_error(option: BodyOption, value: impl std::fmt::Display, rule: &str) -> SceneError {
    SceneError::Option {
        option,
        value: value.to_string(),
        rule: rule.to_owned(),
    }
}

impl BodyOptions {
    /// The cut-off in use: the explicit one, or max rpm × max order × margin.
    pub fn cutoff_hz(&self) -> f64 {
        if self.mode_cutoff_hz > 0.0 {
            self.mode_cutoff_hz
        } else {
            self.max_rpm / 60.0 * self.max_engine_order * AUTO_CUTOFF_MARGIN
        }
    }

    /// Refuses the options that modify the procedural chassis for a body that is `what`.
    fn procedural_only(&self, what: &str) -> Result<(), SceneError> {
        for (set, option) in [
            (self.stiffening_bar, BodyOption::StiffeningBar),
            (self.stiff_front_plate, BodyOption::StiffFrontPlate),
        ] {
            if set {
                return Err(option_error(
                    option,
                    true,
                    &format!("applies to the procedural body only; this vehicle's body is {what}"),
                ));
            }
        }
        Ok(())
    }

    /// Checks every option against its domain.
    pub fn validate(&self) -> Result<(), SceneError> {
        if !(self.mode_cutoff_hz.is_finite() && self.mode_cutoff_hz >= 0.0) {
            return Err(option_error(
                BodyOption::ModeCutoff,
                format!("{} Hz", self.mode_cutoff_hz),
                "must be >= 0 and finite (0: automatic)",
            ));
        }
        for (option, value) in [
            (BodyOption::MaxRpm, self.max_rpm),
            (BodyOption::MaxEngineOrder, self.max_engine_order),
        ] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(option_error(option, value, "must be positive and finite"));
            }
        }
        if !(self.modal_damping_scale.is_finite() && self.modal_damping_scale >= 0.0) {
            return Err(option_error(
                BodyOption::ModalDampingScale,
                self.modal_damping_scale,
                "must be >= 0 and finite",
            ));
        }
        Ok(())
    }
}

/// A model built for a scene, with log lines on how its body was obtained.
pub struct Built {
    /// The coupled engine–mount–body model.
    pub model: CoupledModel,
    /// How the body was obtained (built and reduced, or read from the cache), one log line each.
    pub notes: Vec<String>,
}

/// Builds the coupled model of `vehicle` for `scene`.
pub fn build(
    vehicle: &VehicleConfig,
    scene: SceneKind,
    options: &BodyOptions,
) -> Result<Built, SceneError> {
    vehicle.validate().map_err(|e| e.to_string())?;
    let (body, notes) = match scene {
        SceneKind::Ground => (ReducedChassis::rigid_ground(), Vec::new()),
        SceneKind::ExternalBody => {
            let model = CoupledModel::on_external_body(vehicle).map_err(|e| e.to_string())?;
            return Ok(Built {
                model,
                notes: Vec::new(),
            });
        }
        SceneKind::Body => body(vehicle, options)?,
    };
    let model = CoupledModel::with_body(vehicle, body).map_err(|e| e.to_string())?;
    Ok(Built { model, notes })
}

/// The fixed-interface modes the scene keeps, and how they were chosen (for the log).
fn mode_selection(vehicle: &VehicleConfig, options: &BodyOptions) -> (ModeSelection, String) {
    // A rigid body needs no fixed-interface modes: the constraint modes alone contain its
    // rigid-body motion on the suspension, the only part kept later.
    if !vehicle.effects.chassis_flexibility {
        (
            ModeSelection::Count(0),
            "rigid chassis: rigid-body modes on the suspension only".to_owned(),
        )
    } else if options.max_modes > 0 {
        (
            ModeSelection::Count(options.max_modes),
            format!("{} fixed-interface modes", options.max_modes),
        )
    } else {
        let cutoff = options.cutoff_hz();
        let origin = if options.mode_cutoff_hz > 0.0 {
            format!("cut-off {cutoff:.0} Hz (given)")
        } else {
            format!(
                "automatic cut-off {cutoff:.0} Hz = {} rpm / 60 x order {} x margin {AUTO_CUTOFF_MARGIN}",
                options.max_rpm, options.max_engine_order
            )
        };
        (ModeSelection::CutoffHz(cutoff), origin)
    }
}

/// The vehicle's reduced body alone, driven by forces at its mount points (the body FMU), with
/// the log lines of [`body`].
pub fn build_body_alone(
    vehicle: &VehicleConfig,
    options: &BodyOptions,
) -> Result<(BodyAlone, Vec<String>), SceneError> {
    vehicle.validate().map_err(|e| e.to_string())?;
    let (reduced, notes) = body(vehicle, options)?;
    let weight = crate::model::powertrain::Powertrain::new(
        vehicle.engine.clone(),
        vehicle.effects,
        vehicle.gravity,
    )
    .map_err(|e| e.to_string())?
    .mass()
        * vehicle.gravity.abs();
    let force_limit = crate::model::inputs::BODY_FORCE_LIMIT_WEIGHTS * weight;
    let model = BodyAlone::new(reduced, &vehicle.mounts, &vehicle.outputs, force_limit)
        .map_err(|e| e.to_string())?;
    Ok((model, notes))
}

/// What the reduction of the vehicle's body depends on for these options (procedural chassis,
/// bulk data deck, or Craig-Bampton matrices reduced elsewhere), and a description of the mode
/// selection for the log.
///
/// Long on purpose: one match over the body sources (procedural chassis, deck, reduced
/// matrices), each arm gathering every input of its reduction, so that the cache key sees them all.
pub fn reduction_spec(
    vehicle: &VehicleConfig,
    options: &BodyOptions,
) -> Result<(ReductionSpec, String), SceneError> {
    options.validate()?;
    let body = match &vehicle.body {
        BodyConfig::Procedural { chassis, .. } => {
            let mut chassis = chassis.clone();
            chassis.options.stiffening_bar |= options.stiffening_bar;
            chassis.options.stiff_front_plate |= options.stiff_front_plate;
            BodySource::Procedural(chassis)
        }
        BodyConfig::Nastran {
            path,
            points,
            include_root,
            ..
        } => {
            options.procedural_only("a bulk data deck")?;
            // Streaming over the deck and its INCLUDEs: the key follows every file's content
            // without holding any of them in memory.
            let sha256 =
                file_digest(path, include_root).map_err(|e| format!("bulk data deck: {e}"))?;
            BodySource::Deck(BulkDeckBody {
                path: path.clone(),
                sha256,
                points: points.clone(),
                include_root: include_root.clone(),
            })
        }
        BodyConfig::Dmig {
            path,
            stiffness,
            mass,
            recovery,
            points,
            include_root,
            ..
        } => {
            options.procedural_only("given as Craig-Bampton matrices (DMIG)")?;
            if options.interface_rotations {
                return Err(option_error(
                    BodyOption::InterfaceRotations,
                    true,
                    "does not apply to a body given as DMIG matrices: its interface is the \
                     file's boundary set",
                ));
            }
            let sha256 = file_digest(path, include_root).map_err(|e| format!("DMIG body: {e}"))?;
            BodySource::Dmig(DmigBodySource {
                path: path.clone(),
                sha256,
                stiffness: stiffness.clone(),
                mass: mass.clone(),
                recovery: recovery.clone(),
                points: points.clone(),
                include_root: include_root.clone(),
            })
        }
        BodyConfig::Reduced { .. } => {
            return Err(SceneError::Model(
                "the vehicle's body is already reduced".into(),
            ));
        }
    };
    let interface = vehicle.interface_nodes().map_err(|e| e.to_string())?;
    let (selection, origin) = mode_selection(vehicle, options);
    let spec = ReductionSpec {
        body,
        interface,
        interface_dofs: if options.interface_rotations {
            InterfaceDofs::All
        } else {
            InterfaceDofs::Translations
        },
        selection,
        outputs: vehicle.outputs.clone(),
        ..ReductionSpec::default()
    };
    Ok((spec, origin))
}

/// SHA-256 of a bulk data or DMIG file and the files it includes.
fn file_digest(
    path: &std::path::Path,
    include_root: &Option<std::path::PathBuf>,
) -> Result<String, crate::fe::FeError> {
    let options = crate::nastran::DeckOptions {
        include_root: include_root.clone(),
        ..Default::default()
    };
    crate::nastran::deck_digest(path, &options)
}

/// Sets the modal damping of `body`: the vehicle configuration's body damping, else the body's
/// own (a deck's `TABDMP1` named by `SDAMPING`; a reduced body read from a file keeps its
/// ratios), else the default; the physical part scaled by `scale`. Returns what was applied,
/// for the log, and a warning for every mode damped above critical.
fn apply_damping(
    body: &mut ReducedChassis,
    vehicle: &VehicleConfig,
    scale: f64,
) -> Result<(String, Vec<String>), SceneError> {
    let (applied, origin) = set_damping(body, vehicle, scale)?;
    Ok((applied, overdamped(body, &origin, scale)))
}

/// Overdamped modes are legal (a joint or a damping layer may damp a local mode beyond critical),
/// but a damping table or override that puts a mode there is more often a unit mistake (a G or
/// Q value given as CRIT, a percentage as a ratio): each is named, with its value and origin. The
/// interface modes above the cut-off are damped numerically (at most critical) and not named.
fn overdamped(body: &ReducedChassis, origin: &str, scale: f64) -> Vec<String> {
    let hz = |k: usize| body.omega[k] / (2.0 * std::f64::consts::PI);
    let physical = |k: usize| body.cutoff_hz.is_none_or(|c| hz(k) <= c);
    let over: Vec<usize> = (0..body.zeta.len())
        .filter(|&k| body.zeta[k] > 1.0 && physical(k))
        .collect();
    let scaled = if scale == 1.0 {
        String::new()
    } else {
        format!(", chassis.modalDampingScale = {scale}")
    };
    let mut lines: Vec<String> = over
        .iter()
        .take(5)
        .map(|&k| {
            format!(
                "warning: body mode {} ({:.1} Hz) is damped at {:.3} of critical, above critical \
                 (overdamped), by {origin}{scaled}: accepted; check the table's unit (CRIT is a \
                 fraction of critical, G = 2 CRIT, Q = 1 / (2 CRIT)) and whether a percentage \
                 was meant",
                k + 1,
                hz(k),
                body.zeta[k]
            )
        })
        .collect();
    if over.len() > 5 {
        lines.push(format!(
            "warning: {} more body modes are damped above critical",
            over.len() - 5
        ));
    }
    lines
}

/// [`apply_damping`] without the warnings: what was applied, and where the damping came from.
fn set_damping(
    body: &mut ReducedChassis,
    vehicle: &VehicleConfig,
    scale: f64,
) -> Result<(String, String), SceneError> {
    let given = vehicle.body.damping();
    if given.is_none() {
        if let BodyConfig::Reduced { .. } = vehicle.body {
            for z in &mut body.zeta {
                *z *= scale;
            }
            return Ok((
                format!("modal damping x{scale} (the file's ratios)"),
                "the reduced body file's ratios".to_owned(),
            ));
        }
    }
    let (damping, origin) = match (given, &body.own_damping) {
        (Some(d), _) => (d.clone(), "the vehicle configuration's".to_owned()),
        (None, Some(own)) => (
            BodyDamping::from_table(own.table.clone()),
            format!("the body's {}", own.source),
        ),
        (None, None) => (BodyDamping::default(), "the default".to_owned()),
    };
    let hz: Vec<f64> = body
        .omega
        .iter()
        .map(|w| w / (2.0 * std::f64::consts::PI))
        .collect();
    body.zeta = damping
        .ratios(&hz, body.cutoff_hz, scale)
        .map_err(|e| SceneError::Model(format!("body.damping: {e}")))?;
    let interface = match body.cutoff_hz {
        Some(c) => {
            let above = hz.iter().filter(|f| **f > c).count();
            format!("; {above} interface modes above {c:.1} Hz damped numerically")
        }
        None => String::new(),
    };
    let source = match (given, &body.own_damping) {
        (Some(_), _) => "the vehicle configuration's body.damping".to_owned(),
        (None, Some(own)) => format!("the body's {}", own.source),
        (None, None) => "the default damping".to_owned(),
    };
    Ok((
        format!("modal damping x{scale} ({origin}){interface}"),
        source,
    ))
}

/// The reduced body the scene asks for, from the cache or freshly reduced (timed for the log),
/// with the log lines: how it was obtained, then its warnings (each starting with "warning: ").
pub fn body(
    vehicle: &VehicleConfig,
    options: &BodyOptions,
) -> Result<(ReducedChassis, Vec<String>), SceneError> {
    options.validate()?;
    let flexible = vehicle.effects.chassis_flexibility;
    let started = std::time::Instant::now();
    let (body, origin) = match &vehicle.body {
        BodyConfig::Procedural { .. } | BodyConfig::Nastran { .. } | BodyConfig::Dmig { .. } => {
            let (spec, origin) = reduction_spec(vehicle, options)?;
            let (body, outcome, notes) =
                reduce_cached_with_notes(&spec, &options.cache).map_err(|e| match &spec.body {
                    BodySource::Dmig(d) => format!("DMIG body {}: {e}", d.path.display()),
                    _ => format!("chassis reduction: {e}"),
                })?;
            let source = match outcome {
                CacheOutcome::Hit(path) => format!("read from cache {}", path.display()),
                CacheOutcome::Stored(path) => format!("reduced and cached at {}", path.display()),
                CacheOutcome::Replaced { path, reason } => format!(
                    "reduced and cached at {} (old entry: {reason})",
                    path.display()
                ),
                CacheOutcome::NotStored { reason } => format!("reduced (not cached: {reason})"),
                CacheOutcome::Disabled => "reduced (caching disabled)".to_owned(),
            };
            let what = match &spec.body {
                BodySource::Procedural(chassis) => {
                    let on = |b: bool| if b { "on" } else { "off" };
                    format!(
                        "procedural chassis (Craig-Bampton, {origin}, stiffening bar {}, stiffer \
                         front plate {})",
                        on(chassis.options.stiffening_bar),
                        on(chassis.options.stiff_front_plate)
                    )
                }
                BodySource::Deck(deck) => format!(
                    "bulk data deck {} (Craig-Bampton, {origin})",
                    deck.path.display()
                ),
                BodySource::Dmig(d) => format!(
                    "DMIG body {} (Craig-Bampton matrices {}, {}; {origin})",
                    d.path.display(),
                    d.stiffness,
                    d.mass
                ),
            };
            // The deck's notes (dropped grids, element-shape warnings) go to the log with it.
            let notes: String = notes.iter().map(|n| format!("; {n}")).collect();
            (body, format!("{what}, {source}{notes}"))
        }
        BodyConfig::Reduced { path, .. } => {
            options.procedural_only("a reduced model from a file")?;
            let text = crate::text_file::read_limited(path, crate::text_file::DATA_LIMIT)
                .map_err(|e| format!("reduced body: {e}"))?;
            let body: ReducedChassis = serde_json::from_str(&text)
                .map_err(|e| format!("reduced body {}: {e}", path.display()))?;
            (body, format!("reduced body read from {}", path.display()))
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    let mut body = if flexible {
        body
    } else {
        // The rigid-body modes on the suspension are the body's physical modes here.
        let mut rigid = body.keep_below(RIGID_BODY_HZ);
        rigid.cutoff_hz = rigid.cutoff_hz.map(|_| RIGID_BODY_HZ);
        rigid
    };
    let (damping_origin, warnings) =
        apply_damping(&mut body, vehicle, options.modal_damping_scale)?;
    let note = format!(
        "{origin}, {damping_origin}: {} modes, {:.1}..{:.1} Hz, in {seconds:.2} s",
        body.n_modes(),
        body.omega.first().copied().unwrap_or(0.0) / (2.0 * std::f64::consts::PI),
        body.omega.last().copied().unwrap_or(0.0) / (2.0 * std::f64::consts::PI),
    );
    let mut lines = vec![note];
    lines.extend(warnings);
    Ok((body, lines))
}
