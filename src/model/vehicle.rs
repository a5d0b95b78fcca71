//! The vehicle configuration: which components make the coupled model — the powertrain, the
//! mounts between its brackets and the ground or body, the body source and the body points that
//! are outputs. A scene is a choice among these (rigid ground or the configured body), not a type.
//!
//! JSON: every struct rejects unknown fields, and nothing is silently defaulted. A file is either
//! complete, or declares `"extends": "default"` and is then a JSON merge patch (RFC 7386) on the
//! default vehicle: objects merge key by key, arrays and values replace; an object whose `kind`
//! changes (the body's) replaces the default's. Errors name the field's
//! path.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::effects::Effects;
use super::follower::SpeedFollower;
use super::mount::{MountConfig, MountCurve};
use super::powertrain::config::EngineConfig;
use super::powertrain::defaults::{POWERTRAIN_CG, POWERTRAIN_MASS};
use super::validate::{err, positive, ConfigError};
use crate::chassis::config::ChassisConfig;
use crate::chassis::{SEAT_RAIL, STEERING_WHEEL};
use crate::cms::BodyDamping;

/// Where the elastic body comes from (used when the scene has a body).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum BodyConfig {
    /// The procedural car body ([`crate::chassis`]): its mount nodes are `mount_front_left`,
    /// `mount_front_right`, `mount_rear_left`, `mount_rear_right`; other named nodes include
    /// `steering_wheel` and `seat_rail`.
    Procedural {
        /// The chassis's geometry, sections, materials, trim and suspension.
        chassis: Box<ChassisConfig>,
        /// Modal damping of the body (`None`: [`BodyDamping::default`]).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        damping: Option<BodyDamping>,
    },
    /// A user's body from a Nastran bulk data deck ([`crate::nastran`]), reduced by
    /// Craig-Bampton like the procedural one; `points` names the GRID ids the mounts
    /// (`body_node`) and the outputs refer to. A relative path is taken from the configuration
    /// file's folder. Read from a file, the configuration confines the deck to its own folder
    /// (or below), or to `include_root` if given; the deck's INCLUDE files are confined to the
    /// deck's folder, or to `include_root`.
    Nastran {
        /// The bulk data deck.
        path: PathBuf,
        /// GRID id of every named point (mount body nodes, outputs).
        points: std::collections::BTreeMap<String, u32>,
        /// The folder the deck and its INCLUDE files may lie in (relative: to the
        /// configuration file's folder).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        include_root: Option<PathBuf>,
        /// Modal damping of the body (`None`: the deck's own `TABDMP1` named by `SDAMPING` in
        /// its case control, else [`BodyDamping::default`]).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        damping: Option<BodyDamping>,
    },
    /// A body reduced elsewhere: Craig-Bampton matrices in Nastran `DMIG` form
    /// ([`crate::nastran::read_dmig_file`], [`crate::cms::reduce_external`]), reduced to its
    /// modes with the damping table like the other bodies. `points` names the GRID ids of the
    /// mount body nodes (boundary grids of `stiffness`) and of the outputs (boundary grids or
    /// rows of `recovery`). A relative path is taken from the configuration file's folder, and
    /// the file is confined to that folder, or to `include_root` if given.
    Dmig {
        /// The DMIG (punch) file.
        path: PathBuf,
        /// Name of the stiffness matrix (Nastran writes `KAAX`).
        stiffness: String,
        /// Name of the mass matrix (Nastran writes `MAAX`).
        mass: String,
        /// Name of the recovery matrix of the output points (rows: their DOFs, columns: the
        /// DOFs of `stiffness`), if the outputs are not all boundary grids.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        recovery: Option<String>,
        /// GRID id of every named point (mount body nodes, outputs).
        points: std::collections::BTreeMap<String, u32>,
        /// The folder the file (and its INCLUDE files) may lie in (relative: to the
        /// configuration file's folder).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        include_root: Option<PathBuf>,
        /// Modal damping of the body (`None`: [`BodyDamping::default`]).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        damping: Option<BodyDamping>,
    },
    /// Modal data of an already reduced body: the JSON of a [`crate::cms::ReducedChassis`]
    /// (frequencies, damping ratios, named points with their mode-shape rows). A relative path is
    /// taken from the configuration file's folder.
    Reduced {
        /// The JSON file of the reduced body.
        path: PathBuf,
        /// Modal damping of the body in place of the file's ratios (`None`: the file's).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        damping: Option<BodyDamping>,
    },
}

impl BodyConfig {
    /// The body's modal damping as the configuration gives it (`None`: the body's own, or the
    /// default; see each kind).
    pub fn damping(&self) -> Option<&BodyDamping> {
        match self {
            BodyConfig::Procedural { damping, .. }
            | BodyConfig::Nastran { damping, .. }
            | BodyConfig::Dmig { damping, .. }
            | BodyConfig::Reduced { damping, .. } => damping.as_ref(),
        }
    }
}

/// A deck named by a configuration file must lie in `root` (checked on the resolved paths, so
/// neither `..` nor a symbolic link leads out of it) before anything of it is read.
fn confine_deck(deck: &std::path::Path, root: &std::path::Path) -> Result<(), ConfigError> {
    let root_dir = if root.as_os_str().is_empty() {
        std::path::Path::new(".")
    } else {
        root
    };
    let root = std::fs::canonicalize(root_dir).map_err(|e| {
        err(
            "body.include_root",
            format!("folder {} cannot be used: {e}", root_dir.display()),
        )
    })?;
    let canonical = std::fs::canonicalize(deck)
        .map_err(|e| err("body.path", format!("cannot read {}: {e}", deck.display())))?;
    if canonical.starts_with(&root) {
        Ok(())
    } else {
        Err(err(
            "body.path",
            format!(
                "the deck {} is outside {}, the folder decks are confined to (set \
                 body.include_root to allow another folder)",
                deck.display(),
                root.display()
            ),
        ))
    }
}

/// The complete vehicle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleConfig {
    /// Gravitational acceleration (m/s², acting along −z).
    pub gravity: f64,
    /// The powertrain: crank drive, balance shafts, gas forces, monoblock, housing, ring carriers.
    pub engine: EngineConfig,
    /// Engine mounts in FMU order (`mount[1]` is the first).
    pub mounts: Vec<MountConfig>,
    /// Where the elastic body comes from (used in scene 2).
    pub body: BodyConfig,
    /// Body nodes whose motion is reported (the FMU maps `steeringWheel.*` to `steering_wheel`
    /// and `seat.*` to `seat_rail`).
    pub outputs: Vec<String>,
    /// Default effect switches (the FMU's `effects.*` replace them when the master sets them).
    pub effects: Effects,
    /// How the crank follows the speed set-point (`crank.speedTimeConstant` replaces it when set).
    pub speed_follower: SpeedFollower,
}

fn diag(d: [f64; 3]) -> [[f64; 3]; 3] {
    [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]]
}

/// The paper's four mounts (DESIGN §8): decoupled layout at (±0.30, ±0.40, 0) m from the
/// powertrain CG, rates 51.5 (x), 36.6 (y, crank axis), 48.3 (z) N/mm, loss factor 0.15 at 10 Hz,
/// preloads carrying a quarter of the weight each.
pub fn default_mounts(weight: f64) -> Vec<MountConfig> {
    let (kx, ky, kz) = (51_500.0, 36_600.0, 48_300.0);
    let c = |k: f64| 0.15 * k / (2.0 * std::f64::consts::PI * 10.0);
    let corners = [
        ("front_left", 0.30, 0.40),
        ("front_right", 0.30, -0.40),
        ("rear_left", -0.30, 0.40),
        ("rear_right", -0.30, -0.40),
    ];
    corners
        .iter()
        .map(|&(name, dx, dy)| MountConfig {
            name: name.to_string(),
            active: true,
            bracket: [
                POWERTRAIN_CG[0] + dx,
                POWERTRAIN_CG[1] + dy,
                POWERTRAIN_CG[2],
            ],
            ground_point: None,
            body_node: Some(format!("mount_{name}")),
            axes: diag([1.0, 1.0, 1.0]),
            curves: [
                MountCurve::progressive(kx),
                MountCurve::progressive(ky),
                MountCurve::progressive(kz),
            ],
            damping: [c(kx), c(ky), c(kz)],
            preload: [0.0, 0.0, weight / 4.0],
        })
        .collect()
}

impl Default for VehicleConfig {
    /// The paper's vehicle: the Steyr M13 inline-3 on four mounts in the procedural FIAT Brava
    /// body with the default modal damping ([`BodyDamping::default`]), steering wheel and seat
    /// rail as outputs.
    fn default() -> Self {
        let gravity = 9.81;
        Self {
            gravity,
            engine: EngineConfig::default(),
            mounts: default_mounts(POWERTRAIN_MASS * gravity),
            body: BodyConfig::Procedural {
                chassis: Box::default(),
                damping: Some(BodyDamping::default()),
            },
            outputs: vec![STEERING_WHEEL.to_string(), SEAT_RAIL.to_string()],
            effects: Effects::default(),
            speed_follower: SpeedFollower::default(),
        }
    }
}

/// RFC 7386 JSON merge patch of `patch` onto `target`.
fn merge_patch(target: &mut serde_json::Value, patch: &serde_json::Value) {
    use serde_json::Value;
    match patch {
        Value::Object(p) => {
            // A tagged variant that changes its kind (a body from "procedural" to "nastran") is
            // a new object: merging the old variant's fields into it would make no sense.
            let kind_changes = p
                .get("kind")
                .is_some_and(|k| target.get("kind").is_some_and(|old| old != k));
            if !target.is_object() || kind_changes {
                *target = Value::Object(Default::default());
            }
            if let Value::Object(t) = target {
                for (k, v) in p {
                    if v.is_null() {
                        t.remove(k);
                    } else {
                        merge_patch(t.entry(k.clone()).or_insert(Value::Null), v);
                    }
                }
            }
        }
        other => *target = other.clone(),
    }
}

/// Where in `body` an error lies, which serde reports for the whole of `body`: the kinds are an
/// internally tagged enum, whose content serde buffers, so the path inside is lost. The fields
/// shared by the kinds that carry nested data (`damping`) are read again on their own to find it.
fn body_error_path(body: &serde_json::Value) -> Option<(String, String)> {
    let damping = body.get("damping")?;
    let e =
        serde_path_to_error::deserialize::<_, crate::cms::BodyDamping>(damping.clone()).err()?;
    let inner = e.path().to_string();
    let path = if inner == "." || inner.is_empty() {
        "body.damping".to_owned()
    } else {
        format!("body.damping.{inner}")
    };
    Some((path, format!("{}", e.into_inner())))
}

impl VehicleConfig {
    /// Parses a vehicle configuration (see the module doc for `extends`) and validates it.
    pub fn from_json(text: &str) -> Result<Self, ConfigError> {
        let mut value = super::strict_json::parse(text)
            .map_err(|e| err("json", format!("cannot parse the configuration: {e}")))?;
        if let Some(base) = value.as_object_mut().and_then(|o| o.remove("extends")) {
            if base != "default" {
                return Err(err(
                    "extends",
                    format!("extends = {base} is unknown; the only base is \"default\""),
                ));
            }
            let mut merged = serde_json::to_value(Self::default())
                .map_err(|e| err("json", format!("default configuration: {e}")))?;
            merge_patch(&mut merged, &value);
            value = merged;
        }
        let config: Self = serde_path_to_error::deserialize(value.clone()).map_err(|e| {
            let path = e.path().to_string();
            let inner = if path == "body" {
                body_error_path(&value["body"])
            } else {
                None
            };
            match inner {
                Some((path, message)) => err(path, message),
                None => err(path, format!("{}", e.into_inner())),
            }
        })?;
        config.validate()?;
        Ok(config)
    }

    /// Reads and parses a configuration file; a relative `reduced` body path is resolved against
    /// the file's folder.
    pub fn from_file(path: &std::path::Path) -> Result<Self, ConfigError> {
        let text = crate::text_file::read_limited(path, crate::text_file::CONFIG_LIMIT)
            .map_err(|e| err("file", e))?;
        let mut config = Self::from_json(&text)?;
        let dir = path.parent().unwrap_or(std::path::Path::new(""));
        if let BodyConfig::Reduced { path: body, .. }
        | BodyConfig::Nastran { path: body, .. }
        | BodyConfig::Dmig { path: body, .. } = &mut config.body
        {
            if body.is_relative() {
                *body = dir.join(&*body);
            }
        }
        if let BodyConfig::Nastran {
            path: deck,
            include_root,
            ..
        }
        | BodyConfig::Dmig {
            path: deck,
            include_root,
            ..
        } = &mut config.body
        {
            if let Some(root) = include_root.as_mut().filter(|r| r.is_relative()) {
                *root = dir.join(&*root);
            }
            confine_deck(deck, include_root.as_deref().unwrap_or(dir))?;
        }
        Ok(config)
    }

    /// Serialises the configuration as pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Checks every component; the error names the field and its value.
    pub fn validate(&self) -> Result<(), ConfigError> {
        positive("gravity", self.gravity)?;
        self.engine.validate().map_err(|e| ConfigError {
            field: format!("engine.{}", e.field),
            ..e
        })?;
        if self.effects.ring_carrier_elasticity && self.engine.ring_carriers.is_empty() {
            return Err(err(
                "engine.ring_carriers",
                "ring carrier elasticity is on but no ring carrier is configured",
            ));
        }
        let active = self.mounts.iter().filter(|m| m.active).count();
        if active < 3 {
            return Err(err(
                "mounts",
                format!("{active} active mounts cannot carry the powertrain statically; need at least 3"),
            ));
        }
        for (i, m) in self.mounts.iter().enumerate() {
            m.validate(&format!("mounts[{i}]"))?;
            if let Some(j) = self.mounts[..i].iter().position(|o| o.name == m.name) {
                return Err(err(
                    format!("mounts[{i}].name"),
                    format!("mount name '{}' is also the name of mounts[{j}]", m.name),
                ));
            }
        }
        self.validate_body_points()?;
        if let Some(damping) = self.body.damping() {
            damping.check().map_err(|e| {
                let (field, message) = e.split_once(": ").unwrap_or(("", e.as_str()));
                err(format!("body.damping.{field}"), message.to_string())
            })?;
        }
        if let Some(i) = self.outputs.iter().position(|o| o.trim().is_empty()) {
            return Err(err(
                format!("outputs[{i}]"),
                format!("outputs[{i}] is an empty node name"),
            ));
        }
        self.speed_follower.validate("speed_follower")
    }

    /// Every named point of a bulk-deck body must be a node the vehicle uses (a mount's body
    /// node or an output): a misspelt name would otherwise be ignored; and no two active mounts
    /// may attach to one GRID.
    fn validate_body_points(&self) -> Result<(), ConfigError> {
        let (BodyConfig::Nastran { points, .. } | BodyConfig::Dmig { points, .. }) = &self.body
        else {
            return Ok(());
        };
        let used = |name: &str| {
            self.outputs.iter().any(|o| o == name)
                || self
                    .mounts
                    .iter()
                    .any(|m| m.body_node.as_deref() == Some(name))
        };
        if let Some(name) = points.keys().find(|name| !used(name)) {
            return Err(err(
                format!("body.points.{name}"),
                format!(
                    "body point '{name}' is neither a mount's body_node nor an output ({})",
                    self.outputs.join(", ")
                ),
            ));
        }
        // Two mounts on one grid would make the interface singular far downstream.
        let mut seen: Vec<(u32, usize)> = Vec::new();
        for (i, m) in self.mounts.iter().enumerate().filter(|(_, m)| m.active) {
            let Some(grid) = m.body_node.as_ref().and_then(|n| points.get(n)) else {
                continue;
            };
            if let Some(&(_, j)) = seen.iter().find(|(g, _)| g == grid) {
                let other = &self.mounts[j];
                return Err(err(
                    format!("mounts[{i}].body_node"),
                    format!(
                        "mounts '{}' and '{}' both attach to GRID {grid} (body points '{}' and \
                         '{}'): each mount needs its own grid",
                        other.name,
                        m.name,
                        other.body_node.as_deref().unwrap_or(""),
                        m.body_node.as_deref().unwrap_or("")
                    ),
                ));
            }
            seen.push((*grid, i));
        }
        Ok(())
    }

    /// The body nodes the active mounts attach to, in mount order (the body's interface).
    pub fn interface_nodes(&self) -> Result<Vec<String>, ConfigError> {
        self.mounts
            .iter()
            .enumerate()
            .filter(|(_, m)| m.active)
            .map(|(i, m)| {
                m.body_node.clone().ok_or_else(|| {
                    err(
                        format!("mounts[{i}].body_node"),
                        format!("mount '{}' names no body node for the elastic body", m.name),
                    )
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_round_trips_and_patches_merge_onto_it() {
        let cfg = VehicleConfig::default();
        let back = VehicleConfig::from_json(&cfg.to_json()).expect("round trip");
        assert_eq!(back, cfg);
        let patched = VehicleConfig::from_json(
            r#"{"extends": "default", "engine": {"gas": {"load": 0.5}}, "mounts": []}"#,
        );
        // Arrays replace: no mounts left, which the validation refuses by name.
        assert!(patched.unwrap_err().to_string().contains("0 active mounts"));
        let patched =
            VehicleConfig::from_json(r#"{"extends": "default", "engine": {"gas": {"load": 0.5}}}"#)
                .expect("patch");
        assert_eq!(patched.engine.gas.load, 0.5);
        assert_eq!(patched.mounts, cfg.mounts);
    }

    #[test]
    fn unknown_and_missing_fields_are_errors_that_name_the_field() {
        let e = VehicleConfig::from_json(
            r#"{"extends": "default", "engine": {"crank_drive": {"boer": 0.08}}}"#,
        )
        .unwrap_err();
        assert!(e.to_string().contains("engine.crank_drive"), "{e}");
        assert!(e.to_string().contains("boer"), "{e}");
        let mut value = serde_json::to_value(VehicleConfig::default()).unwrap();
        value["engine"].as_object_mut().unwrap().remove("gas");
        let e = VehicleConfig::from_json(&value.to_string()).unwrap_err();
        assert!(e.to_string().contains("gas"), "{e}");
        let e = VehicleConfig::from_json(r#"{"extends": "mine"}"#).unwrap_err();
        assert!(e.to_string().contains("extends"), "{e}");
    }
}
