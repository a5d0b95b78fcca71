//! The reduced chassis as the coupled model sees it.

use serde::{Deserialize, Serialize};

use super::damping::OwnDamping;

/// A point of the chassis whose motion is recovered from the modal coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecoveryPoint {
    /// e.g. "mount_front_left", "steering_wheel", "seat_rail".
    pub name: String,
    /// FE node id.
    pub node: usize,
    /// Undeformed position, vehicle frame (m).
    pub position: [f64; 3],
    /// `shape[k]`: the point's motion (ux, uy, uz, rx, ry, rz; m and rad, vehicle axes) for a unit
    /// modal coordinate `k`.
    pub shape: Vec<[f64; 6]>,
}

/// A Craig-Bampton reduced, constraint-mode-orthogonalised chassis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReducedChassis {
    /// Natural frequency of each mode, rad/s, ascending (reduced K = diag(ω²), reduced M = I).
    pub omega: Vec<f64>,
    /// Modal damping ratio of each mode.
    pub zeta: Vec<f64>,
    /// Interface (mount) nodes first, then output points.
    pub points: Vec<RecoveryPoint>,
    /// The modes above this frequency (Hz) are the interface modes of the reduction, whose
    /// frequencies follow from the constraint modes, not from the structure: the highest
    /// fixed-interface mode kept (0 if none was). `None`: not known (modal data from a file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff_hz: Option<f64>,
    /// The damping the body brought with it (a deck's `TABDMP1` named by `SDAMPING`), which
    /// `zeta` follows; the scene applies it unless the vehicle configuration gives a damping.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub own_damping: Option<OwnDamping>,
}

impl ReducedChassis {
    /// Number of modes (modal coordinates).
    pub fn n_modes(&self) -> usize {
        self.omega.len()
    }

    /// Rigid ground: a body without modes or points (mounts on ground attach at fixed points).
    pub fn rigid_ground() -> ReducedChassis {
        ReducedChassis {
            omega: Vec::new(),
            zeta: Vec::new(),
            points: Vec::new(),
            cutoff_hz: None,
            own_damping: None,
        }
    }

    /// The point of this name, if the body has it.
    pub fn point(&self, name: &str) -> Option<&RecoveryPoint> {
        self.points.iter().find(|p| p.name == name)
    }

    /// Only the modes below `hz` (e.g. the rigid-body modes on the suspension: a rigid chassis).
    pub fn keep_below(&self, hz: f64) -> ReducedChassis {
        let keep: Vec<usize> = (0..self.n_modes())
            .filter(|k| self.omega[*k] < 2.0 * std::f64::consts::PI * hz)
            .collect();
        ReducedChassis {
            omega: keep.iter().map(|k| self.omega[*k]).collect(),
            zeta: keep.iter().map(|k| self.zeta[*k]).collect(),
            points: self
                .points
                .iter()
                .map(|p| RecoveryPoint {
                    shape: keep.iter().map(|k| p.shape[*k]).collect(),
                    ..p.clone()
                })
                .collect(),
            cutoff_hz: self.cutoff_hz,
            own_damping: self.own_damping.clone(),
        }
    }
}
