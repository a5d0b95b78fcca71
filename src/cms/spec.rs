//! What a reduction depends on: the body description, the interface, the mode selection, the
//! damping and the recovered output points. Its canonical JSON is the cache key.

use serde::{Deserialize, Serialize};

use super::damping::DampingTable;
use super::error::CmsError;
use crate::chassis::config::ChassisConfig;
use crate::chassis::{MOUNT_NAMES, SEAT_RAIL, STEERING_WHEEL};

/// Which DOFs of each mount node form the Craig-Bampton interface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InterfaceDofs {
    /// ux, uy, uz: the mounts transmit forces only (default).
    Translations,
    /// ux, uy, uz, rx, ry, rz: the mounts also transmit moments.
    All,
}

impl InterfaceDofs {
    /// Local node DOFs (0..6 = ux, uy, uz, rx, ry, rz) in the interface.
    pub fn local(self) -> &'static [usize] {
        match self {
            InterfaceDofs::Translations => &[0, 1, 2],
            InterfaceDofs::All => &[0, 1, 2, 3, 4, 5],
        }
    }
}

/// Which fixed-interface normal modes are kept. All constraint modes are always kept, so the
/// static interface compliance stays exact.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModeSelection {
    /// The `n` lowest fixed-interface modes (0: a static, Guyan-like reduction).
    Count(usize),
    /// Every fixed-interface mode below this frequency (Hz).
    CutoffHz(f64),
}

/// A body from a Nastran bulk data deck ([`crate::nastran`]): the file, the SHA-256 of its
/// content (so the cache key changes with the content), and the GRID ids of the named points
/// (mounts, outputs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BulkDeckBody {
    /// The deck's file.
    pub path: std::path::PathBuf,
    /// SHA-256 (hex) of its content and of its INCLUDE files
    /// ([`crate::nastran::deck_digest`]).
    pub sha256: String,
    /// GRID id of every named point.
    pub points: std::collections::BTreeMap<String, u32>,
    /// The folder the deck's INCLUDE files are confined to (`None`: the deck's folder).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub include_root: Option<std::path::PathBuf>,
}

/// A body reduced in another solver: Craig-Bampton matrices in Nastran `DMIG` form
/// ([`crate::nastran::read_dmig_file`]), the SHA-256 of the file, the matrices' names and the
/// GRID ids of the named points. [`crate::cms::reduce_external`] takes it from there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DmigBodySource {
    /// The DMIG (punch) file.
    pub path: std::path::PathBuf,
    /// SHA-256 (hex) of its content and of its INCLUDE files.
    pub sha256: String,
    /// Name of the stiffness matrix (Nastran writes `KAAX`).
    pub stiffness: String,
    /// Name of the mass matrix (Nastran writes `MAAX`).
    pub mass: String,
    /// Name of the recovery matrix of the output points, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recovery: Option<String>,
    /// GRID id of every named point.
    pub points: std::collections::BTreeMap<String, u32>,
    /// The folder the file's INCLUDE files are confined to (`None`: the file's folder).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub include_root: Option<std::path::PathBuf>,
}

/// Which body a reduction reduces.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodySource {
    /// The product's procedural chassis ([`crate::chassis`]), reduced here.
    Procedural(Box<ChassisConfig>),
    /// A user's body from a bulk data deck ([`crate::nastran`]), reduced here.
    Deck(BulkDeckBody),
    /// A body reduced elsewhere (Craig-Bampton matrices), orthogonalised and damped here.
    Dmig(DmigBodySource),
}

impl BodySource {
    /// What the body is, for messages: `procedural chassis`, `bulk data deck <path>`,
    /// `DMIG body <path>`.
    pub fn describe(&self) -> String {
        match self {
            BodySource::Procedural(_) => "procedural chassis".to_owned(),
            BodySource::Deck(d) => format!("bulk data deck {}", d.path.display()),
            BodySource::Dmig(d) => format!("DMIG body {}", d.path.display()),
        }
    }
}

/// Everything the reduction depends on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReductionSpec {
    /// The body to reduce.
    pub body: BodySource,
    /// Named body nodes the engine mounts attach to: they form the interface, in this order.
    pub interface: Vec<String>,
    /// Interface DOFs per mount node.
    pub interface_dofs: InterfaceDofs,
    /// Fixed-interface normal modes to keep.
    pub selection: ModeSelection,
    /// Modal damping of the final (orthogonalised) modes.
    pub damping: DampingTable,
    /// Also turn the FE model's discrete dampers (the suspension) into modal damping,
    /// `ζ_k += φ_kᵀ C φ_k / (2 ω_k)`: the diagonal of the projected damping matrix, neglecting
    /// the coupling it adds between modes. Off by default (ADAMS' table only).
    #[serde(default)]
    pub discrete_dampers: bool,
    /// Named FE nodes recovered after the mount nodes (see [`crate::chassis`] for names).
    pub outputs: Vec<String>,
}

impl Default for ReductionSpec {
    /// The default body, its four mount nodes with translational interface DOFs, the 40 lowest
    /// fixed-interface modes, ADAMS damping, steering wheel and seat rail recovered.
    fn default() -> Self {
        Self {
            body: BodySource::Procedural(Box::default()),
            interface: MOUNT_NAMES.iter().map(|n| format!("mount_{n}")).collect(),
            interface_dofs: InterfaceDofs::Translations,
            selection: ModeSelection::Count(40),
            damping: DampingTable::default(),
            discrete_dampers: false,
            outputs: vec![STEERING_WHEEL.to_string(), SEAT_RAIL.to_string()],
        }
    }
}

impl ReductionSpec {
    /// Checks the fields the FE generator does not check itself.
    pub fn validate(&self) -> Result<(), CmsError> {
        if let ModeSelection::CutoffHz(f) = self.selection {
            if !(f.is_finite() && f > 0.0) {
                return Err(CmsError::InvalidInput(format!(
                    "selection.cutoff_hz = {f} must be finite and > 0"
                )));
            }
        }
        self.damping.validate()?;
        if let BodySource::Dmig(d) = &self.body {
            if self.interface_dofs == InterfaceDofs::All {
                return Err(CmsError::InvalidInput(format!(
                    "interface_dofs = all does not apply to the DMIG body {}: its interface is \
                     the file's boundary set",
                    d.path.display()
                )));
            }
            if self.discrete_dampers {
                return Err(CmsError::InvalidInput(format!(
                    "discrete_dampers does not apply to the DMIG body {}: it has no FE damping \
                     matrix",
                    d.path.display()
                )));
            }
        }
        if self.interface.is_empty() {
            return Err(CmsError::InvalidInput(
                "interface: no node; the mounts must attach somewhere".into(),
            ));
        }
        for (i, name) in self.interface.iter().enumerate() {
            if name.is_empty() {
                return Err(CmsError::InvalidInput(format!(
                    "interface[{i}] is an empty node name"
                )));
            }
            if self.interface[..i].contains(name) {
                return Err(CmsError::InvalidInput(format!(
                    "interface[{i}] = '{name}' is listed twice"
                )));
            }
        }
        if let Some(i) = self.outputs.iter().position(|o| o.is_empty()) {
            return Err(CmsError::InvalidInput(format!(
                "outputs[{i}] is an empty node name"
            )));
        }
        Ok(())
    }

    /// Canonical JSON: struct fields in declaration order, maps sorted, floats round-tripping
    /// exactly, so equal specs give equal text and any changed input changes it.
    pub fn canonical_json(&self) -> Result<String, CmsError> {
        serde_json::to_string(self)
            .map_err(|e| CmsError::InvalidInput(format!("reduction spec to JSON: {e}")))
    }

    /// Parses a spec from JSON; unknown fields are errors.
    pub fn from_json(text: &str) -> Result<Self, CmsError> {
        serde_json::from_str(text)
            .map_err(|e| CmsError::InvalidInput(format!("reduction spec JSON: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_round_trip_is_exact_and_canonical() {
        let mut spec = ReductionSpec {
            interface: vec!["mount_front_left".into(), "mount_rear_left".into()],
            selection: ModeSelection::Count(17),
            ..ReductionSpec::default()
        };
        spec.body = BodySource::Procedural(Box::new(ChassisConfig {
            body_stiffness_scale: 0.1 + 0.2,
            ..ChassisConfig::default()
        }));
        let text = spec.canonical_json().unwrap();
        let back = ReductionSpec::from_json(&text).unwrap();
        assert_eq!(back, spec);
        assert_eq!(back.canonical_json().unwrap(), text);
        assert!(
            text.contains("\"interface\":[\"mount_front_left\",\"mount_rear_left\"]"),
            "{text}"
        );
    }

    #[test]
    fn bad_fields_are_named() {
        let spec = ReductionSpec {
            selection: ModeSelection::CutoffHz(-3.0),
            ..ReductionSpec::default()
        };
        assert!(spec
            .validate()
            .unwrap_err()
            .to_string()
            .contains("cutoff_hz"));
        let spec = ReductionSpec {
            outputs: vec!["steering_wheel".into(), String::new()],
            ..ReductionSpec::default()
        };
        assert!(spec
            .validate()
            .unwrap_err()
            .to_string()
            .contains("outputs[1]"));
        let e = ReductionSpec::from_json("{\"bogus\": 1}").unwrap_err();
        assert!(e.to_string().contains("bogus"), "{e}");
    }
}
