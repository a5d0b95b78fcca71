//! Where each component's coordinates live in the state vector. Nothing else computes offsets.
//!
//! `y = [q_0 … q_{nb−1} | v_0 … v_{nb−1} | φ | ω_c α_c | η_1 … η_m | η̇_1 … η̇_m]`:
//! per powertrain body `q = [u, θ]` (displacement of the reference point, Cardan angles) and
//! `v = [u', ω]` (ω in the vehicle frame); `φ` the crank angle relative to the monoblock; the
//! speed follower's crank speed and acceleration (absent when the crank follows the set-point
//! directly); the body's modal coordinates and rates (none on rigid ground). The powertrain part
//! (everything before `η`) is the "engine block" of the Newton matrix.

use std::ops::Range;

/// Offsets of every component's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateLayout {
    bodies: usize,
    follower: bool,
    modes: usize,
}

impl StateLayout {
    /// The layout of `bodies` powertrain bodies, the speed follower's two states if `follower`,
    /// and `modes` body modes.
    pub fn new(bodies: usize, follower: bool, modes: usize) -> Self {
        Self {
            bodies,
            follower,
            modes,
        }
    }

    /// Number of powertrain bodies.
    pub fn bodies(&self) -> usize {
        self.bodies
    }

    /// Number of body modes.
    pub fn modes(&self) -> usize {
        self.modes
    }

    /// Whether the crank speed is a state (speed follower).
    pub fn has_follower(&self) -> bool {
        self.follower
    }

    /// Position coordinates `[u, θ]` of powertrain body `b`.
    pub fn q(&self, b: usize) -> Range<usize> {
        6 * b..6 * b + 6
    }

    /// Velocities `[u', ω]` of powertrain body `b`.
    pub fn v(&self, b: usize) -> Range<usize> {
        let o = 6 * self.bodies + 6 * b;
        o..o + 6
    }

    /// All powertrain position coordinates (the unknowns of the statics besides `η`).
    pub fn positions(&self) -> Range<usize> {
        0..6 * self.bodies
    }

    /// Crank angle relative to the monoblock.
    pub fn crank_angle(&self) -> usize {
        12 * self.bodies
    }

    /// Crank speed and acceleration of the speed follower.
    pub fn follower_states(&self) -> Option<(usize, usize)> {
        self.follower
            .then(|| (self.crank_angle() + 1, self.crank_angle() + 2))
    }

    /// The powertrain's states (the engine block of the Newton matrix).
    pub fn engine(&self) -> Range<usize> {
        0..self.engine_dim()
    }

    /// Number of powertrain states (the engine block of the Newton matrix).
    pub fn engine_dim(&self) -> usize {
        12 * self.bodies + 1 + if self.follower { 2 } else { 0 }
    }

    /// Modal coordinates η.
    pub fn eta(&self) -> Range<usize> {
        let o = self.engine_dim();
        o..o + self.modes
    }

    /// Modal rates η̇.
    pub fn eta_rate(&self) -> Range<usize> {
        let o = self.engine_dim() + self.modes;
        o..o + self.modes
    }

    /// The vibration coordinates (positions, velocities, modal coordinates and rates): all but
    /// the crank angle and the follower, which carry the engine's running, not its vibration.
    pub fn vibration_coordinates(&self) -> Vec<usize> {
        (0..12 * self.bodies)
            .chain(self.eta())
            .chain(self.eta_rate())
            .collect()
    }

    /// Number of states.
    pub fn dim(&self) -> usize {
        self.engine_dim() + 2 * self.modes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_tile_the_state_vector() {
        for (bodies, follower, modes) in [(1, false, 0), (2, true, 0), (2, true, 7), (1, false, 3)]
        {
            let l = StateLayout::new(bodies, follower, modes);
            let mut seen = vec![0; l.dim()];
            for b in 0..bodies {
                l.q(b).chain(l.v(b)).for_each(|i| seen[i] += 1);
            }
            seen[l.crank_angle()] += 1;
            if let Some((w, a)) = l.follower_states() {
                seen[w] += 1;
                seen[a] += 1;
            }
            l.eta().chain(l.eta_rate()).for_each(|i| seen[i] += 1);
            assert!(seen.iter().all(|&c| c == 1), "{bodies} {follower} {modes}");
            assert_eq!(l.engine().end, l.eta().start);
        }
    }
}
