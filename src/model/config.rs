//! Engine configuration (serde). Defaults: DESIGN §8, tuned to the paper's Table 1 column
//! "engine supported by ground" (tuning rationale in `src/model/defaults.rs`).
//!
//! Frame: ISO 8855 vehicle frame, x forward, y left, z up, origin at the front axle centre on the
//! ground. The engine is transverse: the crank axis is +y, cylinders point to +z in the monoblock.
//! All positions are given in the reference configuration (bodies undeflected), SI units.

use serde::{Deserialize, Serialize};

use super::effects::Effects;
use super::gas::GasModel;
use super::mount_curve::MountCurve;

/// Mass properties of one rigid body (without the internal moving parts).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigidBodyConfig {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the vehicle frame (m); also the body's reference point.
    pub centre_of_mass: [f64; 3],
    /// Inertia tensor about the centre of mass in vehicle axes (kg m²).
    pub inertia: [[f64; 3]; 3],
}

/// One cylinder of the inline engine.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CylinderConfig {
    /// Cylinder axis position along the crank axis relative to the crank centre (m).
    pub y_offset: f64,
    /// Crank throw angle (deg): the cylinder's crank angle after TDC is `φ − throw`.
    pub throw_deg: f64,
    /// Crank angle of this cylinder's firing TDC within the 720° cycle (deg).
    pub firing_tdc_deg: f64,
}

/// Crank drive: geometry, reciprocating and rotating masses, firing order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CrankDriveConfig {
    /// Crank centre (middle of the crank axis) in the vehicle frame (m).
    pub crank_centre: [f64; 3],
    pub bore: f64,
    pub crank_radius: f64,
    pub conrod_length: f64,
    /// Piston + oscillating conrod part per cylinder (kg).
    pub oscillating_mass: f64,
    /// Crank pin + rotating conrod part per cylinder, at the crank radius (kg).
    pub rotating_mass: f64,
    /// Counterweight per throw, opposite the crank pin (kg).
    pub counterweight_mass: f64,
    pub counterweight_radius: f64,
    /// Crankshaft + flywheel mass on the axis (kg) and spin inertia (kg m²).
    pub crank_mass: f64,
    pub crank_axial_inertia: f64,
    pub cylinders: Vec<CylinderConfig>,
}

/// Balance shaft (turning at −1× crank speed) and the extra crank counterweight pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BalanceShaftConfig {
    /// A point of the shaft axis (parallel to the crank axis) in the vehicle frame; the weights sit
    /// at ±spacing/2 from it along y (m).
    pub axis_point: [f64; 3],
    pub shaft_mass: f64,
    pub shaft_axial_inertia: f64,
    /// Each of the two opposed eccentric weights (kg) and its eccentricity (m).
    pub weight_mass: f64,
    pub weight_eccentricity: f64,
    pub weight_spacing: f64,
    /// Angle of the +y weight at φ = 0 (deg from +z towards +x); it turns at −φ.
    pub weight_phase_deg: f64,
    /// Extra crank counterweights (two opposed, on the crank, at ±spacing/2 about the crank centre).
    pub extra_counterweight_mass: f64,
    pub extra_counterweight_radius: f64,
    pub extra_counterweight_spacing: f64,
    /// Angle of the +y extra counterweight at φ = 0 (deg); it turns at +φ.
    pub extra_counterweight_phase_deg: f64,
}

/// Gas pressure source and load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GasConfig {
    pub model: GasModel,
    /// Load between idle (0) and full load (1) for the Wiebe model.
    pub load: f64,
    /// Crankcase pressure acting under the piston (Pa).
    pub crankcase_pressure: f64,
}

impl Default for GasConfig {
    fn default() -> Self {
        Self {
            model: GasModel::default(),
            load: 0.0,
            crankcase_pressure: 1.0e5,
        }
    }
}

/// Linear 6-DOF elastomer bushing (ring carrier) between monoblock and housing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BushingConfig {
    pub name: String,
    /// Location in the vehicle frame (m).
    pub position: [f64; 3],
    /// Stiffness in housing axes: translations x, y, z (N/m), rotations x, y, z (N m/rad).
    pub stiffness: [f64; 6],
    /// Damping in the same order (N s/m, N m s/rad).
    pub damping: [f64; 6],
}

/// One engine mount between a housing bracket and ground (or a chassis node).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MountConfig {
    pub name: String,
    /// A removed mount (paper §7.1: 4 → 3 mounts) carries no force and costs nothing.
    #[serde(default = "default_true")]
    pub active: bool,
    /// Bracket point on the housing in the vehicle frame (m).
    pub bracket: [f64; 3],
    /// Attachment point on ground/chassis (m); `None` means coincident with the bracket.
    #[serde(default)]
    pub attachment: Option<[f64; 3]>,
    /// Local mount axes as rows (unit vectors in the vehicle frame); deflections and forces of the
    /// curves below are along these axes.
    pub axes: [[f64; 3]; 3],
    /// Force–deflection curve per local axis.
    pub curves: [MountCurve; 3],
    /// Viscous damping per local axis (N s/m).
    pub damping: [f64; 3],
    /// Force the mount exerts on the bracket at zero deflection, per local axis (N): the assembly
    /// preload that places the static operating point (DESIGN §4.1).
    pub preload: [f64; 3],
}

fn default_true() -> bool {
    true
}

/// Complete engine configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EngineConfig {
    /// Gravitational acceleration (m/s², acting along −z).
    pub gravity: f64,
    /// Crank angle at the start of a simulation (deg, relative to the monoblock).
    pub start_crank_angle_deg: f64,
    /// Excitation fade-in time (s); 0 switches the excitation on at once.
    pub excitation_fade_in: f64,
    pub crank_drive: CrankDriveConfig,
    pub balance_shaft: BalanceShaftConfig,
    pub gas: GasConfig,
    /// Monoblock structure (cylinders, head, main bearing frame) without the moving parts.
    pub monoblock: RigidBodyConfig,
    /// Housing + gearbox + aggregates (carries the mount brackets).
    pub housing: RigidBodyConfig,
    pub ring_carriers: Vec<BushingConfig>,
    pub mounts: Vec<MountConfig>,
    pub effects: Effects,
}

/// A configuration value that is out of its physical range.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigError {
    /// Dotted path of the offending field, e.g. `mounts[2].curves[1].knots[0].stiffness`.
    pub field: String,
    pub message: String,
}

impl std::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "invalid configuration: {}: {}", self.field, self.message)
    }
}

impl std::error::Error for ConfigError {}

fn err(field: impl Into<String>, message: impl Into<String>) -> ConfigError {
    ConfigError {
        field: field.into(),
        message: message.into(),
    }
}

fn positive(field: &str, v: f64) -> Result<(), ConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(err(
            field,
            format!("{field} = {v} must be a positive finite number"),
        ))
    }
}

fn non_negative(field: &str, v: f64) -> Result<(), ConfigError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(err(
            field,
            format!("{field} = {v} must be a non-negative finite number"),
        ))
    }
}

fn finite(field: &str, v: &[f64]) -> Result<(), ConfigError> {
    match v.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(err(field, format!("{field} contains {x}, must be finite"))),
        None => Ok(()),
    }
}

fn inertia_tensor(field: &str, j: &[[f64; 3]; 3]) -> Result<(), ConfigError> {
    finite(field, &j.concat())?;
    let m = nalgebra::Matrix3::from_fn(|r, c| j[r][c]);
    if (m - m.transpose()).abs().max() > 1e-9 * m.abs().max().max(1e-30) {
        return Err(err(field, format!("{field} = {j:?} must be symmetric")));
    }
    let eig = m.symmetric_eigen().eigenvalues;
    let (a, b, c) = (eig[0], eig[1], eig[2]);
    if a.min(b).min(c) <= 0.0 {
        return Err(err(
            field,
            format!("{field} = {j:?} must be positive definite (eigenvalues {a}, {b}, {c})"),
        ));
    }
    // Triangle inequality of principal moments: otherwise no mass distribution has this tensor.
    let tol = 1e-9 * (a + b + c);
    if a + b < c - tol || a + c < b - tol || b + c < a - tol {
        return Err(err(
            field,
            format!("{field} = {j:?} violates the triangle inequality of principal moments"),
        ));
    }
    Ok(())
}

impl RigidBodyConfig {
    fn validate(&self, field: &str) -> Result<(), ConfigError> {
        positive(&format!("{field}.mass"), self.mass)?;
        finite(&format!("{field}.centre_of_mass"), &self.centre_of_mass)?;
        inertia_tensor(&format!("{field}.inertia"), &self.inertia)
    }
}

impl EngineConfig {
    /// Loads a configuration from JSON; unspecified fields take their defaults. Validates it.
    pub fn from_json(text: &str) -> Result<Self, ConfigError> {
        let cfg: Self = serde_json::from_str(text)
            .map_err(|e| err("json", format!("cannot parse the configuration: {e}")))?;
        cfg.validate()?;
        Ok(cfg)
    }

    /// Serialises the configuration as pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Checks every physical parameter; the error names the field and its value.
    pub fn validate(&self) -> Result<(), ConfigError> {
        positive("gravity", self.gravity)?;
        finite("start_crank_angle_deg", &[self.start_crank_angle_deg])?;
        non_negative("excitation_fade_in", self.excitation_fade_in)?;
        let c = &self.crank_drive;
        finite("crank_drive.crank_centre", &c.crank_centre)?;
        positive("crank_drive.bore", c.bore)?;
        positive("crank_drive.crank_radius", c.crank_radius)?;
        positive("crank_drive.conrod_length", c.conrod_length)?;
        let lambda = c.crank_radius / c.conrod_length;
        if lambda >= 1.0 {
            return Err(err(
                "crank_drive.conrod_length",
                format!("lambda = crank_radius / conrod_length = {lambda} must be < 1 (conrod_length = {})", c.conrod_length),
            ));
        }
        positive("crank_drive.oscillating_mass", c.oscillating_mass)?;
        non_negative("crank_drive.rotating_mass", c.rotating_mass)?;
        non_negative("crank_drive.counterweight_mass", c.counterweight_mass)?;
        non_negative("crank_drive.counterweight_radius", c.counterweight_radius)?;
        non_negative("crank_drive.crank_mass", c.crank_mass)?;
        non_negative("crank_drive.crank_axial_inertia", c.crank_axial_inertia)?;
        if c.cylinders.is_empty() {
            return Err(err(
                "crank_drive.cylinders",
                "at least one cylinder is required",
            ));
        }
        for (i, cyl) in c.cylinders.iter().enumerate() {
            let f = format!("crank_drive.cylinders[{i}]");
            finite(&f, &[cyl.y_offset, cyl.throw_deg, cyl.firing_tdc_deg])?;
            let diff = (cyl.firing_tdc_deg - cyl.throw_deg).rem_euclid(360.0);
            if diff > 1e-6 && diff < 360.0 - 1e-6 {
                return Err(err(
                    format!("{f}.firing_tdc_deg"),
                    format!(
                        "{f}.firing_tdc_deg = {} must be a TDC of the cylinder, i.e. equal to throw_deg = {} modulo 360",
                        cyl.firing_tdc_deg, cyl.throw_deg
                    ),
                ));
            }
        }
        let b = &self.balance_shaft;
        finite("balance_shaft.axis_point", &b.axis_point)?;
        for (name, v) in [
            ("shaft_mass", b.shaft_mass),
            ("shaft_axial_inertia", b.shaft_axial_inertia),
            ("weight_mass", b.weight_mass),
            ("weight_eccentricity", b.weight_eccentricity),
            ("weight_spacing", b.weight_spacing),
            ("extra_counterweight_mass", b.extra_counterweight_mass),
            ("extra_counterweight_radius", b.extra_counterweight_radius),
            ("extra_counterweight_spacing", b.extra_counterweight_spacing),
        ] {
            non_negative(&format!("balance_shaft.{name}"), v)?;
        }
        finite(
            "balance_shaft.weight_phase_deg",
            &[b.weight_phase_deg, b.extra_counterweight_phase_deg],
        )?;
        self.validate_gas()?;
        self.monoblock.validate("monoblock")?;
        self.housing.validate("housing")?;
        for (i, r) in self.ring_carriers.iter().enumerate() {
            let f = format!("ring_carriers[{i}]");
            finite(&format!("{f}.position"), &r.position)?;
            for k in 0..6 {
                non_negative(&format!("{f}.stiffness[{k}]"), r.stiffness[k])?;
                non_negative(&format!("{f}.damping[{k}]"), r.damping[k])?;
            }
        }
        if self.effects.ring_carrier_elasticity && self.ring_carriers.is_empty() {
            return Err(err(
                "ring_carriers",
                "ring carrier elasticity is on but no ring carrier is configured",
            ));
        }
        let active = self.mounts.iter().filter(|m| m.active).count();
        if active < 3 {
            return Err(err("mounts", format!("{active} active mounts cannot carry the powertrain statically; need at least 3")));
        }
        for (i, m) in self.mounts.iter().enumerate() {
            let f = format!("mounts[{i}]");
            finite(&format!("{f}.bracket"), &m.bracket)?;
            if let Some(a) = &m.attachment {
                finite(&format!("{f}.attachment"), a)?;
            }
            let axes = nalgebra::Matrix3::from_fn(|r, c| m.axes[r][c]);
            finite(&format!("{f}.axes"), &m.axes.concat())?;
            let dev = (axes * axes.transpose() - nalgebra::Matrix3::identity())
                .abs()
                .max();
            if dev > 1e-6 || axes.determinant() < 0.0 {
                return Err(err(
                    format!("{f}.axes"),
                    format!("{f}.axes = {:?} must be a right-handed orthonormal frame (rows), deviation {dev}", m.axes),
                ));
            }
            for k in 0..3 {
                m.curves[k]
                    .validate(&format!("{f}.curves[{k}]"))
                    .map_err(|e| err(format!("{f}.curves[{k}]"), e))?;
                non_negative(&format!("{f}.damping[{k}]"), m.damping[k])?;
            }
            finite(&format!("{f}.preload"), &m.preload)?;
        }
        Ok(())
    }

    fn validate_gas(&self) -> Result<(), ConfigError> {
        let g = &self.gas;
        let load = g.load;
        if !(load.is_finite() && (0.0..=1.0).contains(&load)) {
            return Err(err(
                "gas.load",
                format!("gas.load = {load} must lie in [0, 1]"),
            ));
        }
        positive("gas.crankcase_pressure", g.crankcase_pressure)?;
        match &g.model {
            GasModel::Wiebe(w) => {
                if !(w.compression_ratio.is_finite() && w.compression_ratio > 1.0) {
                    return Err(err(
                        "gas.model.compression_ratio",
                        format!(
                            "gas.model.compression_ratio = {} must be > 1",
                            w.compression_ratio
                        ),
                    ));
                }
                for (name, k) in [
                    ("kappa_compression", w.kappa_compression),
                    ("kappa_expansion", w.kappa_expansion),
                ] {
                    if !(k.is_finite() && k > 1.0 && k < 2.0) {
                        return Err(err(
                            format!("gas.model.{name}"),
                            format!("gas.model.{name} = {k} must lie in (1, 2)"),
                        ));
                    }
                }
                if !(w.ivc_deg.is_finite()
                    && w.evo_deg.is_finite()
                    && -360.0 < w.ivc_deg
                    && w.ivc_deg < 0.0
                    && 0.0 < w.evo_deg
                    && w.evo_deg < 360.0)
                {
                    return Err(err(
                        "gas.model.ivc_deg",
                        format!(
                            "need -360 < ivc_deg = {} < 0 < evo_deg = {} < 360",
                            w.ivc_deg, w.evo_deg
                        ),
                    ));
                }
                positive("gas.model.blowdown_deg", w.blowdown_deg)?;
                for (pname, p) in [("idle", &w.idle), ("full_load", &w.full_load)] {
                    let f = format!("gas.model.{pname}");
                    positive(&format!("{f}.pressure_ivc"), p.pressure_ivc)?;
                    non_negative(&format!("{f}.heat"), p.heat)?;
                    let total: f64 = p.stages.iter().map(|s| s.fraction).sum();
                    if p.heat > 0.0 && (total - 1.0).abs() > 1e-6 {
                        return Err(err(
                            format!("{f}.stages"),
                            format!("{f}.stages fractions sum to {total}, must be 1"),
                        ));
                    }
                    for (i, s) in p.stages.iter().enumerate() {
                        let sf = format!("{f}.stages[{i}]");
                        non_negative(&format!("{sf}.fraction"), s.fraction)?;
                        positive(&format!("{sf}.duration_deg"), s.duration_deg)?;
                        non_negative(&format!("{sf}.shape"), s.shape)?;
                        finite(&format!("{sf}.start_deg"), &[s.start_deg])?;
                    }
                }
            }
            GasModel::Table(t) => {
                if t.angle_deg.len() != t.pressure.len() || t.angle_deg.len() < 4 {
                    return Err(err(
                        "gas.model.pressure",
                        format!("pressure table needs matching angle/pressure lists of at least 4 points, got {} and {}", t.angle_deg.len(), t.pressure.len()),
                    ));
                }
                finite("gas.model.angle_deg", &t.angle_deg)?;
                for (i, p) in t.pressure.iter().enumerate() {
                    positive(&format!("gas.model.pressure[{i}]"), *p)?;
                }
            }
        }
        Ok(())
    }
}
