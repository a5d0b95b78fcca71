//! Mount configuration: where the connector sits and its force law.

use serde::{Deserialize, Serialize};

use super::curve::MountCurve;
use crate::model::validate::{err, finite, non_negative, ConfigError};

/// One engine mount between a housing bracket and ground or a body node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MountConfig {
    /// The mount's name (reported in messages and mode descriptions).
    pub name: String,
    /// A removed mount (paper §7.1: 4 → 3 mounts) carries no force and costs nothing.
    #[serde(default = "default_true")]
    pub active: bool,
    /// Bracket point on the housing in the vehicle frame (m).
    pub bracket: [f64; 3],
    /// The attachment when the powertrain stands on rigid ground (scene 1), vehicle frame (m);
    /// absent: coincident with the bracket.
    #[serde(default)]
    pub ground_point: Option<[f64; 3]>,
    /// The body node the mount is attached to when the vehicle has an elastic body (scene 2), by
    /// the name the body source gives it (procedural chassis: `mount_front_left`, …; a bulk deck:
    /// the names of its `points` map).
    #[serde(default)]
    pub body_node: Option<String>,
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

impl MountConfig {
    /// Checks geometry and force law; `field` is the mount's path, e.g. `mounts[2]`.
    pub fn validate(&self, field: &str) -> Result<(), ConfigError> {
        finite(&format!("{field}.bracket"), &self.bracket)?;
        if let Some(a) = &self.ground_point {
            finite(&format!("{field}.ground_point"), a)?;
        }
        if self
            .body_node
            .as_deref()
            .is_some_and(|n| n.trim().is_empty())
        {
            return Err(err(
                format!("{field}.body_node"),
                format!("{field}.body_node is an empty name"),
            ));
        }
        let axes = nalgebra::Matrix3::from_fn(|r, c| self.axes[r][c]);
        finite(&format!("{field}.axes"), &self.axes.concat())?;
        let dev = (axes * axes.transpose() - nalgebra::Matrix3::identity())
            .abs()
            .max();
        if dev > 1e-6 || axes.determinant() < 0.0 {
            return Err(err(
                format!("{field}.axes"),
                format!(
                    "{field}.axes = {:?} must be a right-handed orthonormal frame (rows), deviation {dev}",
                    self.axes
                ),
            ));
        }
        for k in 0..3 {
            self.curves[k]
                .validate(&format!("{field}.curves[{k}]"))
                .map_err(|e| err(format!("{field}.curves[{k}]"), e))?;
            non_negative(&format!("{field}.damping[{k}]"), self.damping[k])?;
        }
        finite(&format!("{field}.preload"), &self.preload)
    }
}
