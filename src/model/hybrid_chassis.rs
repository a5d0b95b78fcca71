//! The reduced chassis the hybrid scene runs with, built from the FE body.
//!
//! Method: modal truncation with the body's own (free-interface, suspension attached) normal
//! modes up to a cut-off frequency — the same modal form as the Craig-Bampton contract
//! ([`ReducedChassis`]: reduced M = I, K = diag(ω²)) but without constraint modes, so the
//! interface's static residual flexibility above the cut-off is missing. The engine mounts are two
//! orders of magnitude softer than the body at its mount nodes, so that residual is small against
//! the mount deflection; the Craig-Bampton reduction of `crate::cms` replaces this builder once it
//! is available, through the same [`ReducedChassis`].
//!
//! Recovery points, in the contract's order: the four engine-mount nodes (`mount_front_left`, …)
//! first, then `steering_wheel` and `seat_rail`. Modal damping as ADAMS defaults (DESIGN §4.3):
//! 1 % below 100 Hz, 10 % below 1 kHz, 100 % above.

use serde::{Deserialize, Serialize};

use crate::cms::{RecoveryPoint, ReducedChassis};
use crate::fe::assembly::assemble;
use crate::fe::chassis::{Chassis, MountLayout, SEAT_RAIL, STEERING_WHEEL};
use crate::fe::chassis_config::ChassisConfig;
use crate::fe::eigen::lowest_modes;
use crate::fe::modal::{describe, ModeDescription};

/// What the chassis reduction depends on (every field enters the cache key).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChassisReduction {
    /// The FE body description.
    pub body: ChassisConfig,
    /// Keep the modes up to this frequency (Hz).
    pub cutoff_hz: f64,
    /// At most this many modes.
    pub max_modes: usize,
}

impl Default for ChassisReduction {
    fn default() -> Self {
        Self {
            body: ChassisConfig::default(),
            cutoff_hz: 200.0,
            max_modes: 60,
        }
    }
}

/// Modal damping ratio by frequency, ADAMS defaults.
pub fn default_damping(frequency_hz: f64) -> f64 {
    if frequency_hz < 100.0 {
        0.01
    } else if frequency_hz < 1000.0 {
        0.10
    } else {
        1.0
    }
}

impl ChassisReduction {
    /// Checks the reduction settings.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.cutoff_hz.is_finite() && self.cutoff_hz > 0.0) {
            return Err(format!(
                "chassis mode cut-off {} Hz must be positive and finite",
                self.cutoff_hz
            ));
        }
        if !(1..=400).contains(&self.max_modes) {
            return Err(format!(
                "chassis mode count {} must lie in 1..=400",
                self.max_modes
            ));
        }
        Ok(())
    }

    /// Builds the body, solves its lowest `max_modes` modes and keeps those up to the cut-off.
    pub fn reduce(&self) -> Result<ReducedChassis, String> {
        self.reduce_described().map(|(r, _)| r)
    }

    /// [`Self::reduce`], with the FE description (torsion, steering wheel, …) of every kept mode.
    pub fn reduce_described(&self) -> Result<(ReducedChassis, Vec<ModeDescription>), String> {
        self.validate()?;
        let body = Chassis::build(&self.body).map_err(|e| format!("chassis body: {e}"))?;
        let asm = assemble(&body.mesh).map_err(|e| format!("chassis assembly: {e}"))?;
        let n_free = asm.dofs.n_free();
        let wanted = self.max_modes.min(n_free.saturating_sub(1)).max(1);
        let modes = lowest_modes(&asm.k, &asm.m, wanted, -1.0)
            .map_err(|e| format!("chassis modes: {e}"))?;
        let keep: Vec<usize> = modes
            .frequencies_hz()
            .iter()
            .enumerate()
            .filter(|(_, f)| **f <= self.cutoff_hz)
            .map(|(k, _)| k)
            .collect();
        if keep.is_empty() {
            return Err(format!(
                "no chassis mode lies below the cut-off {} Hz",
                self.cutoff_hz
            ));
        }
        let omega: Vec<f64> = keep
            .iter()
            .map(|&k| modes.eigenvalues[k].max(0.0).sqrt())
            .collect();
        let zeta = omega
            .iter()
            .map(|w| default_damping(w / (2.0 * std::f64::consts::PI)))
            .collect();
        let mut named = body
            .mount_nodes(MountLayout::Four)
            .map_err(|e| format!("chassis mount nodes: {e}"))?;
        for name in [STEERING_WHEEL, SEAT_RAIL] {
            let node = body.node(name).map_err(|e| format!("chassis: {e}"))?;
            named.push((name.to_string(), node));
        }
        let points = named
            .into_iter()
            .map(|(name, node)| {
                let x = body.mesh.nodes[node];
                let shape = keep
                    .iter()
                    .map(|&k| {
                        let mut row = [0.0; 6];
                        for (d, v) in row.iter_mut().enumerate() {
                            if let Some(g) = asm.dofs.global(node, d) {
                                *v = modes.shapes[(g, k)];
                            }
                        }
                        row
                    })
                    .collect();
                RecoveryPoint {
                    name,
                    node,
                    position: [x.x, x.y, x.z],
                    shape,
                }
            })
            .collect();
        let mut descriptions =
            describe(&body.mesh, &asm, &modes).map_err(|e| format!("chassis modes: {e}"))?;
        descriptions.truncate(keep.len());
        Ok((
            ReducedChassis {
                omega,
                zeta,
                points,
            },
            descriptions,
        ))
    }
}
